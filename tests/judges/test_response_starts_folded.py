"""R-7.0-09/-10 over a recording read a window at a time (``wire.ResponseStarts``) hold
their observations folded (memory22): each distinct value's first :class:`Measured` once
and each reply its index, one by one again from the first tainted one. The findings are
those of the observations one by one (every field: verdict, distribution, evidence, the
reply cited), and what is held no longer grows ~650 bytes a reply."""

from __future__ import annotations

import tracemalloc
from dataclasses import asdict
from math import isnan
from statistics import median

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import timing, wire
from conformance.judges.stalled import stalled_interval
from conformance.judges.timing import Measured, StampUncertainty, Window, combine_local
from conformance.links.host_stall import Stall
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1
from conformance.view.runs import Segment
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


# -- counted, not indexed (memory24) --------------------------------------------------------
# Where no place or order is read (one uncertainty for every stamp, no stalls of the tool's
# host) the folds count each reply and gap instead of indexing it: the findings are still
# those of the observations one by one, in every field.


def _gap_findings_one_by_one(segs, stamps) -> list:
    """R-7.0-12 and R-7.0-01 as judge_gaps' list path judges them: every gap observed, in
    order, with its place (``_observe_each``); every gap in or maybe in R-7.0-01's band
    listed (``_two_passes``)."""
    from tests.judges.test_tolerance_use_one_pass import _two_passes

    gaps = wire._cut_gaps(segs)
    observed = wire._observe_each(gaps, stamps, {})
    return [
        combine_local("R-7.0-12", observed, "character gap", real_time=False),
        _two_passes([(g, w) for g, w, *_ in gaps], stamps.base),
    ]


@settings(max_examples=120, deadline=None)
@given(
    st.randoms(use_true_random=False),
    st.integers(1, 40),
    st.integers(1, 9),
    st.sampled_from([0.0, 0.02, 0.2]),
    st.sampled_from([0.0, 1e-6, 0.3e-3]),
)
def test_counted_gaps_are_the_gaps_one_by_one(rng, n, per, odd, base) -> None:
    """ReplyGaps a window at a time, counted (zero gaps, negative zeros, NaN stamps,
    multi-line text, later runs, gaps in and past the band): the one-by-one findings."""
    from tests.judges.test_gaps_by_run import _negative_zero, _segments

    segs = _segments(n, rng, odd)
    if odd:
        segs[n // 2 : n // 2] = [_negative_zero("0D0!"), _negative_zero("1D0!")]
    stamps = StampUncertainty(base)
    gaps = wire.ReplyGaps(stamps)
    for k in range(0, len(segs), per):
        gaps.add(segs[k : k + per])
    assert not gaps._alike.observed.placed  # counted, not indexed
    expected = _gap_findings_one_by_one(segs, stamps)
    assert [_same(f) for f in gaps.findings()] == [_same(f) for f in expected]


measured_values = st.sampled_from([0.0084, 0.010, 0.005, 0.018, -0.0, 0.0, float("nan")]) | (
    st.floats(-1e-3, 30e-3, allow_nan=False)
)


def _one_by_one(observations):
    """``timing.distribution`` on its one-by-one path (neither grouped nor tallied)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(timing, "_grouped", lambda _o: None)
        mp.setattr(timing, "_tallied", lambda _o: None)
        return timing.distribution(observations)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(measured_values, uncertainties), min_size=1, max_size=60),
    st.randoms(use_true_random=False),
    st.sampled_from([EARLY, LATE]),
)
def test_a_distribution_one_by_one_is_that_of_its_values_not_their_order(
    drawn, rng, window
) -> None:
    """A counted fold gives each value back as often as it came, not in the order it came:
    the one-by-one distribution must not depend on that order, NaNs among them (sorted
    last; ``sorted`` left a NaN where it stood and moved the others around it). Without a
    NaN it is what ``sorted``, ``min`` and ``statistics.median`` give, as before."""
    observed = [Measured(window, v, u, []) for v, u in drawn]
    shuffled = list(observed)
    rng.shuffle(shuffled)
    found = _one_by_one(observed)
    assert repr(found) == repr(_one_by_one(shuffled))
    if not any(isnan(v) or isnan(u) for v, u in drawn):
        values = sorted(v for v, _u in drawn)
        slacks = [timing._slack(window.lo, window.hi, v) for v, _u in drawn]
        assert found.min_ms == (timing._ms(values[0]) or 0.0)
        assert found.max_ms == (timing._ms(values[-1]) or 0.0)
        assert found.median_ms == (timing._ms(median(values)) or 0.0)
        assert found.uncertainty_ms == (timing._ms(median(u for _v, u in drawn)) or 0.0)
        assert found.margin_ms == (timing._ms(min(slacks)) or 0.0)


def _held(feed) -> list[int]:
    """Bytes held (tracemalloc) at each point ``feed`` yields, from before it starts."""
    held = []
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for _ in feed:
            held.append(tracemalloc.get_traced_memory()[0] - before)
    finally:
        tracemalloc.stop()
    return held


def test_counted_replies_hold_no_more_after_20000() -> None:
    """20,000 replies of three delays on a capture's grid (no stalls), 50 a window: what
    the two rules hold does not grow with the replies past the first 2,000 (base-s68
    indexed each, 12 bytes a reply a rule: ~0.43 MB more by 20,000)."""
    starts = wire.ResponseStarts(StampUncertainty(1e-5))

    def feed():
        drawn = [("0M!", (0.0084, 0.010, 0.012)[k % 3], "00011\r\n") for k in range(20_000)]
        for k, segs in enumerate(_windows(drawn, 50)):
            starts.add(segs)
            if (k + 1) * 50 in (2_000, 20_000):
                yield

    early, late = _held(feed())
    assert late - early < 20_000, (early, late)
    found = starts.findings()
    assert [f.verdict.name for f in found] == ["PASS", "PASS"]
    assert found[0].observed == found[1].observed == 20_000
    assert found[1].distribution.count == 20_000


def _exact_replies(n: int) -> list[Segment]:
    """``n`` replies of 20 characters, each from a whole second, the characters 2**-7 s long
    and apart by 2**-12 or 2**-11 s: times a float holds exactly, so the gaps take three
    values however long the recording (as a capture's sample grid gives a few)."""
    segs = []
    for k in range(n):
        t, chars = float(k), []
        for i, c in enumerate("0+1.23-45.6+7.8912\r\n"):
            chars.append(Event(EventKind.CHAR, DUT, t, t + 2**-7, wire=to_wire_7e1(ord(c))))
            t += 2**-7 + (2**-12, 2**-11, 0.0)[(i + k) % 3]
        segs.append(Segment(None, [], chars, text=f"{k % 3}D0!"))
    return segs


def test_counted_gaps_hold_no_more_after_20000() -> None:
    """20,000 character gaps of three values (1,100 replies, 64 a window): what R-7.0-12
    holds does not grow with the gaps past the first 2,000 (base-s68 indexed each: 12
    bytes a gap, ~0.2 MB more by 20,000)."""
    segs = _exact_replies(1_100)
    gaps = wire.ReplyGaps(StampUncertainty(1e-5))

    def feed():
        fed = 0
        for k in range(0, len(segs), 64):
            gaps.add(segs[k : k + 64])
            before, fed = fed, len(gaps._alike.observed)
            if before < 2_000 <= fed:
                yield
        yield

    early, late = _held(feed())
    assert late - early < 20_000, (early, late)
    found = gaps.findings()
    assert len(gaps._alike.observed.distinct) == 9  # three values at each of three commands
    assert found[0].observed == found[0].distribution.count == 1_100 * 19
    assert [f.verdict.name for f in found] == ["PASS", "PASS"]
