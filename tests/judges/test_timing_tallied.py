"""``timing.distribution`` over observations that are not all plain :class:`Measured`
against one window (the recorder's breaks and command character gaps are
:class:`MeasuredAsJudged`, a few held back as whole findings) tallies each distinct object
and how often it comes (``timing._tallied``, memory20) instead of three lists, a sort order
and a median's copy as long as the observations: the same distribution as one by one, and
a peak that does not grow with how many there are."""

from __future__ import annotations

import tracemalloc

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import timing
from conformance.judges.timing import (
    Measured,
    MeasuredAsJudged,
    Window,
    combine,
    distribution,
)

GAP = Window("R-7.0-13", "command character gap", high=1.66e-3)
BREAK = Window("R-7.0-02", "break length", low=12e-3)
MARKING = Window("R-7.0-06", "marking after the break", low=8.33e-3)

values = st.floats(-0.5e-3, 20e-3, allow_nan=False) | st.sampled_from(
    [0.0, -0.0, 1.66e-3, 12e-3, 8.33e-3, 1.2e-3]
)
uncertainties = st.sampled_from([0.0, 0.4e-3, 0.4e-3, 1e-5, 2e-3])


def _one_by_one(observations):
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(timing, "_grouped", lambda _o: None)
        mp.setattr(timing, "_tallied", lambda _o: None)
        return distribution(observations)


@st.composite
def mixed(draw):
    """Distinct objects of several kinds and windows, each coming one or more times."""
    distinct: list = []
    for i in range(draw(st.integers(1, 10))):
        window = draw(st.sampled_from([GAP, BREAK, MARKING]))
        v, u = draw(values), draw(uncertainties)
        kind = draw(st.sampled_from(["judged", "judged", "plain", "finding", "combined"]))
        if kind == "judged":
            distinct.append(MeasuredAsJudged(window, v, u, [f"break at t={i}"]))
        elif kind == "plain":
            distinct.append(Measured(window, v, u, [f"in {i}"]))
        elif kind == "finding":
            distinct.append(window.judge(v, u, [f"at {i}"]))
        else:  # a finding standing for several, its distribution several values
            inner = [MeasuredAsJudged(window, v + k * 1e-4, u, []) for k in range(3)]
            distinct.append(combine(window.requirement, inner, "interval"))
    picks = draw(st.lists(st.integers(0, len(distinct) - 1), min_size=1, max_size=400))
    return [distinct[i] for i in picks]


@settings(max_examples=300, deadline=None)
@given(mixed())
def test_tallied_distribution_is_one_by_one(observations):
    assert distribution(observations) == _one_by_one(observations)


def test_breaks_are_tallied_not_listed():
    """The recorder's many breaks of a few lengths go the tallied way (not one by one)."""
    lengths = [MeasuredAsJudged(BREAK, (12 + k / 10) * 1e-3, 0.4e-3, []) for k in range(5)]
    observed = [lengths[i % 5] for i in range(1000)]
    assert timing._grouped(observed) is None
    assert timing._tallied(observed) is not None
    assert distribution(observed) == _one_by_one(observed)


def test_peak_does_not_grow_with_the_observations():
    """200,000 observations of 300 distinct gaps (an hour of a busy bus's command character
    gaps, R-7.0-13): distribution's own peak stays under 0.5 MB (one by one: ~9 MB)."""
    distinct = [MeasuredAsJudged(GAP, k * 5e-6, 0.4e-3, []) for k in range(300)]
    observed = [distinct[(i * 7) % 300] for i in range(200_000)]
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        tallied = distribution(observed)
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    assert peak < 0.5e6, peak
    assert tallied == _one_by_one(observed)


def test_uneven_slacks_of_one_value_go_one_by_one():
    """Equal values against different windows have different slacks: one by one picks the
    first's, so the tally gives way (and the distribution is the one by one's)."""
    a = MeasuredAsJudged(GAP, 1e-3, 0.0, [])
    b = MeasuredAsJudged(BREAK, 1e-3, 0.0, [])
    observed = [b, a, a, b]
    assert timing._distribution_of_tallies(timing._tallied(observed)) is None
    assert distribution(observed) == _one_by_one(observed)
