"""The recorder folds' observations counted by object (``timing.Counted``, memory26): an
hour of a busy bus's breaks, markings and command character gaps were three lists of a
pointer each (0.6 MB at the recorder pass's end, 2.5 MB at four hours); counted, what
:func:`~conformance.judges.timing.combine` makes of them is the same finding, field for
field, as of the list in order, and what they hold does not grow with how many."""

from __future__ import annotations

import math
import tracemalloc

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import timing
from conformance.judges.recorder import breaks, commands
from conformance.judges.timing import Counted, MeasuredAsJudged, MeasuredIn, Window, combine
from conformance.verdicts import Finding, Verdict

GAP = Window("R-7.0-13", "command character gap", high=1.66e-3)
BREAK = Window("R-7.0-02", "break length", low=12e-3)

values = st.floats(-0.5e-3, 20e-3, allow_nan=False) | st.sampled_from(
    [0.0, -0.0, 1.66e-3, 12e-3, 1.2e-3, 1.7e-3, math.nan]
)
uncertainties = st.sampled_from([0.0, 0.4e-3, 1e-5, 2e-3, math.nan])


class _Where:
    def __init__(self, i: int) -> None:
        self.i = i

    def at(self) -> str:
        return f"0D0! at t={self.i}"


@st.composite
def one_rule(draw):
    """A fold's observations of one window: judged intervals (plain and ``in <where>``), a
    few as whole findings (a stall held, a break held back, none of them the others'
    figures), each coming one or more times, in any order."""
    window = draw(st.sampled_from([GAP, BREAK]))
    distinct: list = []
    for i in range(draw(st.integers(1, 12))):
        v, u = draw(values), draw(uncertainties)
        kind = draw(st.sampled_from(["judged", "judged", "in", "finding", "inconclusive"]))
        if kind == "judged":
            distinct.append(MeasuredAsJudged(window, v, u, [f"break at t={i}"]))
        elif kind == "in":
            distinct.append(MeasuredIn(window, v, u, _Where(i)))
        elif kind == "finding":
            distinct.append(window.judge(v, u, [f"at {i}"]))
        else:
            distinct.append(
                Finding(window.requirement, Verdict.INCONCLUSIVE, f"held {i}", observed=1)
            )
    picks = draw(st.lists(st.integers(0, len(distinct) - 1), min_size=0, max_size=300))
    return window, [distinct[i] for i in picks]


def _counted(observations) -> Counted:
    counted = Counted()
    for o in observations:
        counted.append(o)
    return counted


@settings(max_examples=300, deadline=None)
@given(one_rule())
def test_counted_combines_as_the_list(drawn):
    window, observations = drawn
    counted = _counted(observations)
    assert len(counted) == len(observations)
    rid = window.requirement
    mine, theirs = combine(rid, counted.alike(), "interval"), combine(rid, observations, "interval")
    assert repr(mine) == repr(theirs)  # (NaN figures compared as written)
    # read one by one: each distinct object as often as it came, in first-come order
    alike = counted.alike()
    assert sorted(map(id, alike)) == sorted(map(id, observations))
    assert list({id(o): o for o in alike}) == list({id(o): o for o in observations})


@settings(max_examples=150, deadline=None)
@given(one_rule())
def test_counted_one_by_one_distribution_is_the_lists(drawn):
    """Where the distribution is worked out one by one (past ``TALLIED_MAX`` distinct
    objects, a NaN, a value of two slacks), the counted order gives the list's figures."""
    _window, observations = drawn
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(timing, "_tallied", lambda _o: None)
        mine = timing.distribution(_counted(observations).alike())
        theirs = timing.distribution(observations)
    assert repr(mine) == repr(theirs)  # (NaN figures compared as written)


class _Listed(list):
    """The folds' observations as a list (base-s69's), read as the list itself."""

    def alike(self):
        return self


def test_folds_hold_the_distinct_observations_only():
    """A window of 40 breaks and commands of a few lengths added 200 and 800 times: counted,
    the folds grow by nothing per observation (listed: 8 bytes each, ~0.5 MB here)."""
    from conformance.transcript import TOOL, Event, EventKind, to_wire_7e1
    from conformance.view.segments import read_view

    events, t = [], 0.0
    for n in range(40):
        events.append(Event(EventKind.BREAK, TOOL, t, t + 0.0125 + (n % 3) * 1e-4))
        t += 0.0125 + 0.0095
        for c in f"{n % 10}D0!":
            events.append(Event(EventKind.CHAR, TOOL, t, t + 8.33e-3, wire=to_wire_7e1(ord(c))))
            t += 8.33e-3 + (n % 4) * 1e-5
        t += 0.05
    view = read_view(events)

    def grown(times: int) -> int:
        folds = (breaks.Breaks(0.4e-3), commands.CharacterGaps(0.4e-3))
        tracemalloc.start()
        try:
            for _ in range(times):
                for fold in folds:
                    fold.add(view)
            return tracemalloc.get_traced_memory()[0]
        finally:
            tracemalloc.stop()

    grown(10)  # what the first adds make once (caches)
    growth = grown(800) - grown(200)  # 600 * 40 * (2 + 3) observations more
    assert growth < 20_000, f"{growth} bytes for 120,000 observations more"


def test_listed_folds_give_the_counted_findings(monkeypatch):
    """The same windows through the folds counted and listed: every finding equal."""
    from conformance.transcript import TOOL, Event, EventKind, to_wire_7e1
    from conformance.view.segments import read_view

    views = []
    t = 0.0
    for w in range(6):
        events = []
        for n in range(30):
            events.append(Event(EventKind.BREAK, TOOL, t, t + 0.0118 + (n % 5) * 2e-4))
            t += 0.0125 + 0.0083 + (n % 2) * 1e-4
            for c in f"{(n + w) % 10}M!":
                events.append(Event(EventKind.CHAR, TOOL, t, t + 8.33e-3, wire=to_wire_7e1(ord(c))))
                t += 8.33e-3 + (n % 7) * 3e-4
            t += 0.1
        views.append(read_view(events))

    def findings():
        folds = (breaks.Breaks(0.4e-3), commands.CharacterGaps(0.4e-3))
        for v in views:
            for fold in folds:
                fold.add(v)
        return [f for fold in folds for f in fold.findings()]

    counted = findings()
    monkeypatch.setattr(breaks, "Counted", _Listed)
    monkeypatch.setattr(commands, "Counted", _Listed)
    assert findings() == counted
    assert any(f.verdict is not Verdict.PASS for f in counted)  # deviations shown alike
