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


def reference(edges: list[int], width: float) -> tuple[list[int], int, int]:
    """The filter's rule edge by edge on the whole list at once: what any chunking of the
    same edges must give."""
    kept: list[int] = []
    removed = beside = 0
    last_removed = float("-inf")
    for e in edges:
        if kept and e - kept[-1] < width:
            kept.pop()
            removed += 1
            last_removed = e
            continue
        beside += e - last_removed < width
        last_removed = float("-inf")
        kept.append(e)
    return kept, removed, beside


@pytest.mark.parametrize("seed", range(40))
def test_any_chunking_gives_the_rule_applied_edge_by_edge(seed):
    """Random edges (mostly bit-long runs, some spikes and bounces) cut into random chunks:
    the fast path for chunks without a short pulse and the edge-by-edge path agree with the
    rule applied to the whole list."""
    import random

    rng = random.Random(seed)
    edges, t = [], 0
    # even seeds: a noisy line (4 edges in 10 a spike or a bounce); odd ones: a clean line
    # with a rare spike, so that most chunks take the fast path
    noisy = [1, 2, 5, 9, 833, 833, 1666, 4000, 9, 833]
    clean = [833] * 30 + [1666] * 10 + [4000] * 5 + [3]
    for _ in range(rng.randrange(1, 300)):
        t += rng.choice(clean if seed % 2 else noisy)
        edges.append(t)
    cuts = sorted(
        {*rng.sample(range(1, len(edges) + 1), k=min(len(edges), rng.randrange(1, 20))), len(edges)}
    )
    chunks = [edges[a:b] for a, b in zip([0, *cuts], cuts, strict=False)]
    f = GlitchFilter(10)
    got = [e for c in f(chunks) for e in c]
    assert (got, f.removed, f.beside_edges) == reference(edges, 10)
