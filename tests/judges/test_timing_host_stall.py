"""Timing read across a stall of the tool's own host is no evidence against the sensor
(truth29; conformance.links.host_stall, conformance.judges.stalled).

When the tool's process is paused, what the sensor sent meanwhile is stamped at the late
burst that delivers it: a reply begun in time reads as begun late, two characters back to
back read 120 ms apart (a reply begun later than the view's cut is no reply to time: the
stalls here hold a start back 30 ms). Here each is a hand-typed run of this tool, the
link's NOTE of the stall after the burst: a deviation read across the stall is set aside
with the stall named (INCONCLUSIVE where its reply was not observed often enough outside
one, and that command wanted again); the same deviation with no NOTE, or the NOTE
elsewhere, FAILs as ever. The live judges take the stalls as an argument base-s66 lacks;
the recording's judges (``test_recorded_*``) FAILed the stalled runs on base-s66."""

from __future__ import annotations

import pytest

from conformance.judges import wire
from conformance.judges.timing import StampUncertainty
from conformance.links import host_stall
from conformance.links.base import LinkInfo
from conformance.offline.sensor_windows import SensorRecords, bus_windows, sensor_records
from conformance.replay.recording_link import RecordingLink, RecordingSpec
from conformance.transcript import DUT, TOOL, Event, EventKind, Transcript
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

U = 1e-4
STALL = 0.15  # s: the pause the link measured
WHY = "the tool's host stalled 150 ms during this read"
#: a real-time link's stamps (a local figure: rare deviations decided by place) and a flat one
STAMPS = pytest.mark.parametrize(
    "stamps",
    [StampUncertainty(U), StampUncertainty(U, local=lambda _s, _e: U)],
    ids=["flat", "real-time"],
)


class Run:
    """Exchanges typed one after another: a break, the command, the reply ``delay`` after
    it (a ``gap`` before its character ``at``), and the link's NOTE of a stall where asked
    (after the reply's last character: the burst the stall held back)."""

    def __init__(self) -> None:
        self.events: list[Event] = []
        self.t = 0.0

    def exchange(
        self,
        command: str,
        reply: str,
        *,
        delay: float = 0.010,
        gap: float = 0.0,
        at: int = 0,
        stalled: bool = False,
    ) -> None:
        self.events.append(Event(EventKind.BREAK, TOOL, self.t, self.t + 0.0125, uncertainty=U))
        cmd = chars(TOOL, command, self.t + 0.0215, uncertainty=U)
        first = chars(DUT, reply[:at] if at else reply, cmd[-1].end + delay, uncertainty=U)
        rest = chars(DUT, reply[at:], first[-1].end + gap, uncertainty=U) if at else []
        self.events += cmd + first + rest
        end = (rest or first)[-1].end
        if stalled:
            self.events.append(Event(EventKind.NOTE, TOOL, end, end, text=_note()))
        self.t = end + 0.3

    def findings(self, judge, stamps: StampUncertainty, *, noted: bool = True) -> dict:
        stalls = host_stall.stalls(self.events) if noted else []
        return {f.requirement: f for f in judge(segments(self.events), stamps, stalls)}

    def recorded(self, *, noted: bool = True) -> SensorRecords:
        """The run judged as a recording of this tool's run is (a real-time link's
        transcript: rare deviations decided by place), its NOTEs dropped unless ``noted``."""
        kept = [e for e in self.events if noted or e.kind is not EventKind.NOTE]
        info = LinkInfo(kind="transcript", can_break=True, timing_uncertainty=U)
        link = RecordingLink(RecordingSpec("t.jsonl", "jsonl"), info, Transcript(kept), U)
        return sensor_records(link, bus_windows(link), "0")


def _note() -> str:
    return host_stall.note_text(STALL)


def _late_start(stalled: bool, others: int = 3) -> Run:
    """``others`` a! answered in time and 0I! whose reply reads 30 ms late."""
    run = Run()
    for _ in range(others):
        run.exchange("0!", "0\r\n")
    run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n", delay=0.030, stalled=stalled)
    return run


@STAMPS
def test_a_reply_start_read_across_a_stall_is_not_late(stamps):
    found = _late_start(True).findings(wire.judge_response_start, stamps)["R-7.0-10"]
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail and "30.00 ms" in found.detail


def test_the_same_late_start_outside_any_stall_fails():
    """(On a real-time link one late start among four is left to be observed again.)"""
    stamps = StampUncertainty(U)
    run = _late_start(False)
    assert run.findings(wire.judge_response_start, stamps)["R-7.0-10"].verdict is Verdict.FAIL
    # the stall noted elsewhere (before the run) moved none of its stamps
    run.events.insert(0, Event(EventKind.NOTE, TOOL, -1.0, -1.0, text=_note()))
    assert run.findings(wire.judge_response_start, stamps)["R-7.0-10"].verdict is Verdict.FAIL


@STAMPS
def test_a_stalled_late_start_beside_an_unstalled_one_still_fails(stamps):
    run = _late_start(True)
    run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n", delay=0.030)
    run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n", delay=0.030)
    found = run.findings(wire.judge_response_start, stamps)["R-7.0-10"]
    assert found.verdict is Verdict.FAIL, found.detail


def test_a_stalled_start_at_a_reply_seen_often_in_time_is_set_aside_and_passes():
    """The same command observed in time 6 times outside any stall: the stalled one is set
    aside, named, and the rule PASSes on the rest."""
    run = Run()
    for _ in range(6):
        run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n")
    run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n", delay=0.030, stalled=True)
    stamps = StampUncertainty(U, local=lambda _s, _e: U)
    found = run.findings(wire.judge_response_start, stamps)["R-7.0-10"]
    assert found.verdict is Verdict.PASS, found.detail
    assert "1 reply set aside, read across a stall" in found.detail and WHY in found.detail
    assert wire.starts_to_confirm(segments(run.events), stamps, host_stall.stalls(run.events)) == []


def test_a_stalled_start_seen_too_rarely_is_observed_again():
    """The session sends the command again whose only deviation a stall may have made and
    that was too rarely observed outside one to stand for it."""
    run = _late_start(True)
    stamps = StampUncertainty(U, local=lambda _s, _e: U)
    stalls = host_stall.stalls(run.events)
    assert wire.starts_to_confirm(segments(run.events), stamps, stalls) == ["0I!"]
    assert wire.starts_to_confirm(segments(run.events), stamps) == ["0I!"]  # a FAIL, rare


def _long_gap(stalled: bool) -> Run:
    """Three D0 replies back to back and one whose fourth character came 120 ms late."""
    run = Run()
    for _ in range(3):
        run.exchange("0D0!", "0+1.50+2.25\r\n")
    run.exchange("0D1!", "0+3.50+4.25\r\n", gap=0.120, at=4, stalled=stalled)
    return run


@STAMPS
def test_a_character_gap_read_across_a_stall_is_not_a_fail(stamps):
    found = _long_gap(True).findings(wire.judge_gaps, stamps)["R-7.0-12"]
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail


def test_the_same_gap_outside_any_stall_fails():
    """(On a real-time link one gap this rare among 48 is left to be observed again.)"""
    flat = StampUncertainty(U)
    found = _long_gap(True).findings(wire.judge_gaps, flat, noted=False)["R-7.0-12"]
    assert found.verdict is Verdict.FAIL
    assert WHY not in found.detail


def _by_rule(findings) -> dict:
    return {f.requirement: f for f in findings}


def _late_starts_recorded(stalled: bool) -> Run:
    """Three a! in time and two 0I! whose replies read 30 ms late: two of five deviate,
    frequent enough on a real-time link to be the device's (sustained)."""
    run = _late_start(stalled)
    run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n", delay=0.030, stalled=stalled)
    return run


def test_recorded_late_starts_across_stalls_are_not_a_fail():
    """What the paused run's whole-run case reads: base-s66 FAILed R-7.0-10 on them."""
    found = _by_rule(_late_starts_recorded(True).recorded().response_start)["R-7.0-10"]
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail and "2 replies set aside" in found.detail


def test_recorded_late_starts_outside_any_stall_fail():
    run = _late_starts_recorded(True)
    found = _by_rule(run.recorded(noted=False).response_start)["R-7.0-10"]
    assert found.verdict is Verdict.FAIL and WHY not in found.detail


def _long_gaps_recorded(stalled: bool) -> Run:
    """A D0 reply back to back and three whose fourth character came 120 ms late: 3 of
    48 gaps deviate, frequent enough to be the device's."""
    run = Run()
    run.exchange("0D0!", "0+1.50+2.25\r\n")
    for _ in range(3):
        run.exchange("0D1!", "0+3.50+4.25\r\n", gap=0.120, at=4, stalled=stalled)
    return run


def test_recorded_gaps_across_stalls_are_not_a_fail():
    found = _by_rule(_long_gaps_recorded(True).recorded().gaps)["R-7.0-12"]
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail


def test_recorded_gaps_outside_any_stall_fail():
    found = _by_rule(_long_gaps_recorded(True).recorded(noted=False).gaps)["R-7.0-12"]
    assert found.verdict is Verdict.FAIL and WHY not in found.detail


def test_no_stalled_start_is_observed_again_where_the_rest_fail():
    """Every reply late outside the stalls (response-too-late under pauses): the rule FAILs
    whatever a repeat of the stalled one shows; the paused run re-probed them all."""
    run = Run()
    for _ in range(3):
        run.exchange("0!", "0\r\n", delay=0.020)
    run.exchange("0I!", "014CONFORM EMULATOR1.0\r\n", delay=0.030, stalled=True)
    stamps = StampUncertainty(U, local=lambda _s, _e: U)
    stalls = host_stall.stalls(run.events)
    assert wire.starts_to_confirm(segments(run.events), stamps, stalls) == []
    found = run.findings(wire.judge_response_start, stamps)["R-7.0-10"]
    assert found.verdict is Verdict.FAIL
    assert "1 reply set aside, read across a stall" in found.detail
