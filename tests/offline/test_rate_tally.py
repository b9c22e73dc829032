"""A decode-quality note's bit-rate figures from a bounded tally (issue 22): the min, median
and max :class:`~conformance.offline.decode_quality.RateTally` gives are the very floats
``min``, ``statistics.median`` and ``max`` of the listed values give, in batches of any
size, past its distinct-value limit and with ``-0.0`` beside ``0.0`` (equal, printed
apart), and it keeps one entry a distinct value, not a character."""

from __future__ import annotations

import statistics

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.offline.decode_quality import RateTally

rates = st.floats(allow_nan=False, allow_infinity=False, width=32)
few = st.sampled_from([-1.25, -0.0, 0.0, 0.5, 2.0, 3.0e-3])


def _figures(values: list[float]) -> tuple[str, str, str]:
    low, mid, high = min(values), statistics.median(values), max(values)
    return repr(low), repr(mid), repr(high)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.lists(rates | few, max_size=12), min_size=1, max_size=6), st.booleans())
def test_the_tally_gives_the_listed_values_figures(batches, small):
    values = [v for b in batches for v in b]
    if not values:
        return
    tally = RateTally()
    if small:
        tally.DISTINCT = 3  # past it: the values listed from there on
    for b in batches:
        tally.extend(b)
    assert bool(tally)
    found = tuple(repr(v) for v in tally.summary())
    assert found == _figures(values)


def test_a_busy_capture_s_rates_stay_a_tally():
    """Many characters of few distinct errors: one entry each, never listed."""
    tally = RateTally()
    for _ in range(1000):
        tally.extend([0.25, -0.5, 0.25, 1.0])
    assert tally.listed is None and len(tally.counts) == 3
    assert tally.summary() == (-0.5, 0.25, 1.0)


@pytest.mark.parametrize("zeros", [[0.0, -0.0], [-0.0, 0.0], [0.0, 0.0, -0.0, 1.0]])
def test_signed_zeros_keep_their_order(zeros):
    tally = RateTally()
    for v in zeros:
        tally.extend([v])
    assert tuple(repr(v) for v in tally.summary()) == _figures(zeros)
