"""The bulk decoder's bits at their centres (``uart_bulk._centre_levels``) against what a
binary search of every centre in the window's edges counts, as the decoder read them before:
the same levels, bit for bit, with edges placed exactly on a centre's float, one unit in the
last place either side of it, at the start bit and past the stop bit; and the parity table
made once per framing as the framing's own check says."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture import uart_bulk
from conformance.capture.uart import Framing


def _searched(Wf: np.ndarray, starts: np.ndarray, T: float, nbits: int) -> np.ndarray:
    """The levels as the decoder read them: every centre searched among the edges."""
    centres = Wf[starts][:, None] + (np.arange(nbits) + 0.5) * T
    count = np.searchsorted(Wf, centres, "right") - (starts + 1)[:, None]
    return (count & 1).astype(np.int64)


def _inner(Wf: np.ndarray, starts: np.ndarray, T: float, nbits: int):
    """The decoder's inner edges of each frame (its window: 1.1 frames) and their frame."""
    frame_span = nbits * T * 1.1
    j = np.searchsorted(Wf, Wf[starts] + frame_span, "left")
    m = j - starts - 1
    owner = np.repeat(np.arange(starts.size), m)
    first = np.cumsum(m) - m
    at = np.arange(owner.size) - first[owner] + starts[owner] + 1
    return Wf[at], owner


OFFSET = st.one_of(
    st.floats(0.0, 12.0),  # anywhere in (and past) the frame, in bits
    st.integers(0, 10).map(lambda k: ("centre", k)),  # exactly on a centre's float
    st.tuples(st.integers(0, 10), st.sampled_from([-1, 1])).map(lambda x: ("ulp", *x)),
)


@st.composite
def windows(draw):
    """Frames of a window: each a start tick and the ticks (floats) of its inner edges."""
    T = draw(st.sampled_from([100_000 / 1200, 1_000_000 / 1200, 48_000 / 1200, 64.0, 80.0]))
    nbits = 10
    t = draw(st.floats(0, 1e7))
    edges: list[float] = []
    starts: list[int] = []
    for _ in range(draw(st.integers(1, 12))):
        start = float(np.floor(t))
        starts.append(len(edges))
        edges.append(start)
        inner = []
        for off in draw(st.lists(OFFSET, max_size=9)):
            if isinstance(off, tuple) and off[0] == "centre":
                x = start + (off[1] + 0.5) * T
            elif isinstance(off, tuple):
                x = float(np.nextafter(start + (off[1] + 0.5) * T, np.inf * off[2]))
            else:
                x = start + off * T
            inner.append(max(x, start))
        edges += sorted(inner)
        t = max(edges[-1], start + 10 * T) + 12 * T + draw(st.floats(0, 50)) * T
    return np.array(edges), np.array(starts, dtype=np.int64), T, nbits


@settings(max_examples=300, deadline=None)
@given(windows())
def test_levels_match_the_searched_centres(window):
    Wf, starts, T, nbits = window
    edge_at, owner = _inner(Wf, starts, T, nbits)
    got = uart_bulk._centre_levels(edge_at, Wf[starts], owner, starts.size, T, nbits)
    assert got.tolist() == _searched(Wf, starts, T, nbits).tolist()


def test_an_edge_on_a_centre_counts_for_it():
    """The search's "right" side: an edge exactly at a centre's float is read at that centre."""
    T, nbits = 100_000 / 1200, 10
    start = 1234.0
    Wf = np.array([start, start + 3.5 * T, start + 12 * T])  # start bit, low until bit 3
    starts = np.array([0])
    edge_at, owner = _inner(Wf, starts, T, nbits)
    got = uart_bulk._centre_levels(edge_at, Wf[starts], owner, 1, T, nbits)
    assert got.tolist() == _searched(Wf, starts, T, nbits).tolist()
    assert got[0].tolist() == [0, 0, 0, 1, 1, 1, 1, 1, 1, 1]


@pytest.mark.parametrize("text", ["7E1", "7O1", "8N1"])
def test_parity_table_is_the_framings_check(text):
    framing = Framing.parse(text)
    table = uart_bulk._parity_errors(framing)
    assert table.tolist() == [not framing.parity_ok(w) for w in range(256)]
    assert uart_bulk._parity_errors(Framing.parse(text)) is table  # made once per framing


def test_nan_as_none():
    values = [1.5, float("nan"), -0.0, float("nan")]
    got = uart_bulk._nan_as_none(values)
    assert values[1] != values[1]  # the list given is left as it was
    assert uart_bulk._nan_as_none([]) == [] and uart_bulk._nan_as_none([2.0]) == [2.0]
    assert got[0] == 1.5 and got[1] is None and got[3] is None
    assert str(got[2]) == "-0.0"
