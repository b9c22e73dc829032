"""``timing.distribution`` figures each distinct :class:`Measured` once, however often it
comes (a run's tens of thousands of character gaps are a few hundred distinct ones): the
distribution, and ``combine``'s finding over it, are the ones figured one by one."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import timing
from conformance.judges.timing import Measured, Window, combine, combine_local, distribution
from conformance.verdicts import MAX_TICKS

GAP = Window("R-7.0-12", "marking between response characters", high=1.66e-3, tolerance=0.0)
START = Window("R-7.0-09", "first response start bit", low=8.33e-3, tolerance=0.4e-3)
OTHER = Window("R-7.0-12", "marking between response characters", high=1.66e-3, tolerance=0.0)

values = st.floats(-0.5e-3, 3e-3, allow_nan=False) | st.sampled_from(
    [0.0, -0.0, 1.66e-3, 2.0e-3, 2.5e-3, 1.7e-3]
)
uncertainties = st.sampled_from([0.0, 0.0, 0.1e-3, 0.4e-3, 1e-5])


def _one_by_one(monkeypatch, observations):
    with monkeypatch.context() as m:
        m.setattr(timing, "_grouped", lambda _o: None)
        m.setattr(timing, "_tallied", lambda _o: None)  # memory20's tally: one by one here
        return distribution(observations)


@st.composite
def repeated(draw, window=GAP):
    """Distinct observations, each standing for one or more, in a drawn order."""
    distinct = [
        Measured(window, draw(values), draw(uncertainties), [f"in reply to {i}"])
        for i in range(draw(st.integers(1, 12)))
    ]
    picks = draw(st.lists(st.integers(0, len(distinct) - 1), min_size=1, max_size=600))
    return [distinct[i] for i in picks]


@settings(max_examples=300, deadline=None)
@given(repeated())
def test_grouped_distribution_is_one_by_one(observations):
    with pytest.MonkeyPatch.context() as mp:
        assert timing._grouped(observations) is not None
        assert distribution(observations) == _one_by_one(mp, observations)


@settings(max_examples=100, deadline=None)
@given(repeated())
def test_combined_finding_is_the_same(observations):
    """``combine`` and ``combine_local`` over the same observations, grouped or not."""
    with pytest.MonkeyPatch.context() as mp:
        grouped = combine("R-7.0-12", observations, "character gap")
        local = combine_local(
            "R-7.0-12", [(o, False, ("0D0!", "", 1)) for o in observations], "gap", real_time=False
        )
        # each one its own object: nothing for combine to take once for several
        copies = [
            Measured(o._window, o.measured, o.uncertainty, o.evidence_lines) for o in observations
        ]
        assert grouped == combine("R-7.0-12", copies, "character gap")
        mp.setattr(timing, "_grouped", lambda _o: None)
        assert grouped == combine("R-7.0-12", observations, "character gap")
        assert grouped == combine("R-7.0-12", copies, "character gap")
        assert local == combine_local(
            "R-7.0-12", [(o, False, ("0D0!", "", 1)) for o in observations], "gap", real_time=False
        )


def test_many_observations_sampled_alike(monkeypatch):
    """More than MAX_TICKS observations: the sampled ticks, median and margin agree."""
    distinct = [Measured(GAP, v * 1e-5, (v % 3) * 1e-5, [str(v)]) for v in range(-20, 200)]
    observations = [distinct[(i * 7919) % len(distinct)] for i in range(5001)]
    assert len(observations) > MAX_TICKS
    for n in (5001, 5000, 4999):
        assert distribution(observations[:n]) == _one_by_one(monkeypatch, observations[:n])


def test_one_by_one_where_not_one_window_of_plain_measurements(monkeypatch):
    """Two windows (even with equal edges), a NaN: one by one, as before."""
    a = Measured(GAP, 1e-3, 0.0, None)
    b = Measured(OTHER, 1e-3, 0.0, None)
    c = Measured(START, 9e-3, 0.0, None)
    nan = Measured(GAP, float("nan"), 0.0, None)
    for observations in ([a, b], [a, c, a], [a, nan, a], [nan]):
        assert timing._grouped(observations) is None
    assert timing._grouped([]) is None
    assert distribution([a, a, c]) == _one_by_one(monkeypatch, [a, a, c])
    assert distribution([]) is None
