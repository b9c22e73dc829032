"""The glitch filter on hand-written edges: what it removes, what it keeps, and what it says
about the edges it kept."""

from __future__ import annotations

import pytest

from conformance.capture.glitch_filter import GlitchFilter


def filtered(edges: list[int], width: float = 10, chunk: int = 3) -> tuple[list[int], GlitchFilter]:
    f = GlitchFilter(width)
    chunks = [edges[i : i + chunk] for i in range(0, len(edges), chunk)]
    return [e for c in f(chunks) for e in c], f


def test_a_spike_on_the_idle_line_goes_and_moves_no_edge():
    kept, f = filtered([0, 5000, 5001, 9000])
    assert kept == [0, 9000] and f.removed == 1 and f.beside_edges == 0


def test_a_chattering_edge_is_kept_once_at_its_last_bounce_and_said_to_be_uncertain():
    kept, f = filtered([0, 1000, 1001, 1002, 1003, 1004, 2000])
    assert kept == [0, 1004, 2000]  # levels still alternate: falls and rises in turn
    assert f.removed == 2 and f.beside_edges == 2


def test_a_spike_just_before_an_edge_leaves_that_edge_uncertain():
    kept, f = filtered([0, 995, 996, 1000, 2000])
    assert kept == [0, 1000, 2000] and f.beside_edges == 1


@pytest.mark.parametrize("chunk", [1, 2, 3, 7, 100])
def test_chunk_boundaries_change_nothing(chunk):
    edges = [0, 100, 101, 300, 301, 302, 900, 905, 2000, 2001, 2002, 2003, 3000]
    kept, f = filtered(edges, chunk=chunk)
    assert kept == [0, 302, 3000]  # a fall, a rise, a fall: as the line went
    assert (f.removed, f.beside_edges) == (5, 2)


def test_clean_edges_pass_untouched_and_a_zero_width_is_off():
    edges = [0, 100, 200, 300, 1000]
    assert filtered(edges)[0] == edges and filtered(edges)[1].removed == 0
    assert filtered([0, 1, 2, 3], width=0)[0] == [0, 1, 2, 3]
