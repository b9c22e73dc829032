"""R-7.0-09/-10 over a recording read a window at a time (``wire.ResponseStarts``) hold
their observations folded (memory22): each distinct value's first :class:`Measured` once
and each reply its index, one by one again from the first tainted one. The findings are
those of the observations one by one (every field: verdict, distribution, evidence, the
reply cited), and what is held no longer grows ~650 bytes a reply."""

from __future__ import annotations

import tracemalloc
from dataclasses import asdict

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import wire
from conformance.judges.stalled import stalled_interval
from conformance.judges.timing import Measured, StampUncertainty, Window, combine_local
from conformance.links.host_stall import Stall
from conformance.transcript import Event
from tests.judges.test_start_observations_shared import _exchange

EARLY = Window("R-7.0-09", "reply start", low=7.93e-3)
LATE = Window("R-7.0-10", "reply start", high=15e-3)
STALL = Stall(0.0, 1.0, 120.0)

delays = st.sampled_from([0.0084, 0.010, 0.010, 0.005, 0.018, 0.0158, float("nan"), -0.0, 0.0])
uncertainties = st.sampled_from([0.0, 0.4e-3, 0.4e-3, 2e-3, float("nan")])
places = st.sampled_from([("0M!", "00011", 0), ("0D0!", "0+1", 0), ("0I!", "014TEST", 0)])
taints = st.sampled_from(["clean", "clean", "clean", "irregular", "stall"])


def _same(found) -> str:
    """Every field of ``found``, a NaN equal to a NaN."""
    return repr(asdict(found))


def _observation(window: Window, k: int, delay: float, u: float, taint: str, place):
    judged = Measured(window, delay, u, [f"reply {k}"])
    if taint == "stall":
        return (stalled_interval(judged, STALL), STALL, place)
    return (judged, taint == "irregular", place)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.tuples(delays, uncertainties, taints, places), max_size=40),
    st.booleans(),
    st.booleans(),
    st.sampled_from([EARLY, LATE]),
)
def test_folded_findings_are_the_one_by_one_findings(drawn, placed, real_time, window) -> None:
    """Repeats, NaNs, zeros of both signs, deviations, and tainted ones (the link's
    irregular stamps, a stall of the tool's host) anywhere among them."""
    observations = [_observation(window, k, *d) for k, d in enumerate(drawn)]
    # ResponseStarts keeps no place only where none is read: a virtual clock, no stalls
    placed = placed or real_time or any(taint != "clean" for *_, taint, _p in drawn)
    folded = wire._FoldedStarts(placed=placed)
    half = len(observations) // 2
    folded.add(observations[:half])
    folded.add(observations[half:])
    rid = window.requirement
    one_by_one = combine_local(rid, list(observations), "reply", real_time=real_time)
    found = combine_local(rid, folded.observed(), "reply", real_time=real_time)
    assert _same(found) == _same(one_by_one)
    assert found.evidence == one_by_one.evidence  # the reply cited


def _windows(exchanges: list[tuple[str, float | None, str]], per: int):
    """The exchanges' segments, ``per`` exchanges a window."""
    for first in range(0, len(exchanges), per):
        events: list[Event] = []
        for k, (command, delay, reply) in enumerate(exchanges[first : first + per]):
            events += _exchange((first + k) * 0.5, command, delay, reply)
        yield wire.segments(events)


def _as_before(windows, stamps, stalls) -> list:
    """ResponseStarts as it was: every observation listed, one by one."""
    early: list = []
    late: list = []
    last = None
    for segs in windows:
        e, la, last = wire._start_observations(segs, stamps, last, stalls)
        early += e
        late += la
    real = stamps.local is not None
    return [
        combine_local("R-7.0-09", early, "reply", real_time=real),
        combine_local("R-7.0-10", late, "reply", real_time=real),
    ]


exchanges = st.lists(
    st.tuples(
        st.sampled_from(["0M!", "0D0!", "0I!"]),
        st.sampled_from([0.0084, 0.010, 0.010, 0.005, 0.018, None]),
        st.sampled_from(["00011\r\n", "0+1.5\r\n", "0+2.5\r\n"]),
    ),
    min_size=1,
    max_size=24,
)
stampings = st.sampled_from(
    [
        StampUncertainty(0.0),
        StampUncertainty(0.5e-3),
        StampUncertainty(0.5e-3, local=lambda _s, _e: 0.5e-3),  # host-stamped
        StampUncertainty(0.5e-3, local=lambda s, _e: 3e-3 if 2.0 < s < 4.0 else 0.5e-3),
    ]
)
stall_lists = st.sampled_from([None, [], [Stall(1.4, 2.6, 150.0)], [Stall(0.0, 30.0, 90.0)]])


@settings(max_examples=150, deadline=None)
@given(exchanges, st.integers(1, 8), stampings, stall_lists)
def test_windowed_findings_are_as_before(drawn, per, stamps, stalls) -> None:
    """Replies in time, early, late and unanswered commands (a reply may answer the one
    before, across a window's cut), on a virtual clock, a host-stamped one and one whose
    stamps are irregular somewhere, with and without stalls of the tool's host."""
    starts = wire.ResponseStarts(stamps, stalls)
    for segs in _windows(drawn, per):
        starts.add(segs)
    expected = _as_before(_windows(drawn, per), stamps, stalls)
    assert [_same(f) for f in starts.findings()] == [_same(f) for f in expected]


def test_held_memory_does_not_grow_by_the_reply() -> None:
    """3,000 replies of three delays, 50 a window: one by one held ~2 MB (two tuples, a
    Measured and its evidence maker a reply); folded, their indexes (12 bytes a reply a rule) and
    the three values' objects."""
    drawn = [("0M!", (0.0084, 0.010, 0.012)[k % 3], "00011\r\n") for k in range(3000)]
    stamps = StampUncertainty(0.4e-3)
    starts = wire.ResponseStarts(stamps)
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for segs in _windows(drawn, 50):
            starts.add(segs)
        held = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert held < 0.25e6, held
    verdicts = [f.verdict.name for f in starts.findings()]
    assert verdicts == ["PASS", "PASS"]
    assert starts.findings()[0].observed == 3000
