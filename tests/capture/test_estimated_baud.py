"""The bit rate a capture's shortest pulses suggest (``decode._estimated_baud``), found by a
partial sort in numpy: the same figure as the full sort in Python it replaced
(``_estimated_baud_sorted``) for every prefix of edges, ties, repeats, decreasing steps and
short prefixes included, and the Python sort where numpy would not hold the ticks as int64."""

from __future__ import annotations

import random

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture.decode import _estimated_baud, _estimated_baud_sorted

RATES = (100_000.0, 1_000_000.0, 24e6)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(min_value=0, max_value=2**40), max_size=300),
    st.sampled_from(RATES),
)
def test_any_ticks_give_the_sorted_figure(prefix: list[int], rate: float) -> None:
    assert _estimated_baud(prefix, rate) == _estimated_baud_sorted(prefix, rate)


def test_a_capture_like_prefix_gives_the_sorted_figure() -> None:
    """Edges of 1200-baud frames at 100 kHz with a few glitches and repeated stamps, as
    long as a decode's prefix (thousands of edges)."""
    rng = random.Random(7)
    for _ in range(50):
        ticks, t = [], rng.randrange(10**6)
        for _ in range(rng.randrange(8, 9000)):
            t += rng.choice((0, 1, 2, 83, 83, 83, 166, 249, 500, 2000))
            ticks.append(t)
        assert _estimated_baud(ticks, 1e5) == _estimated_baud_sorted(ticks, 1e5)


def test_fewer_than_eight_rising_gaps_suggest_nothing() -> None:
    assert _estimated_baud([0, 5, 5, 3, 9, 9, 12, 20, 21], 1e5) is None
    assert _estimated_baud([], 1e5) is None
    assert _estimated_baud(list(range(0, 90, 10)), 1e5) == 1e5 / 10


def test_ticks_numpy_cannot_hold_take_the_python_sort() -> None:
    huge = [2**70 + 10 * k for k in range(20)]
    assert _estimated_baud(huge, 1e5) == 1e5 / 10
    floats = [0.0, 10.5, 21.0, 31.5, 42.0, 52.5, 63.0, 73.5, 84.0, 94.5]
    assert _estimated_baud(floats, 1e5) == _estimated_baud_sorted(floats, 1e5) == 1e5 / 10.5
