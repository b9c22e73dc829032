"""Silence, R-7.0-01's band and the service-request wait read a stall of the tool's own
host (truth30; conformance.judges.stalled).

Hand-made records of this tool: a probe, a gap or a wait with the link's NOTE of a stall
over its decisive moment is no evidence (INCONCLUSIVE, the stall named); the same outside
any stall is judged as ever (the controls). Each stalled case failed on base-s67 (its
``silent`` and ``held_by`` took no stall; R-7.0-01 FAILed the gap; the wait with no
character before the D read was not marked)."""

from __future__ import annotations

from conformance.emulator import sim_sensor
from conformance.judges import measurements as judge
from conformance.judges import wire
from conformance.judges.exchanges import silent
from conformance.judges.stalled import held_by
from conformance.judges.timing import StampUncertainty
from conformance.links import host_stall
from conformance.protocol.commands import parse_command
from conformance.sensor.session import SensorSession
from conformance.tool_recorder.records import OK, Attempt, Exchange, Measurement
from conformance.tool_recorder.stalled_reads import mark_waits
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict, failed, passed
from tests.judges.test_timing_host_stall import Run
from tests.support.hand_events import chars

STALL = host_stall.Stall(0.9, 1.1, 150.0)
WHY = "the tool's host stalled 150 ms during this read"
U = 1e-3


def _probes():
    """A sim sensor's silent probe (1!), answered probe (0!) and control (0!)."""
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    quiet = sensor.master.raw("1!", break_first=True)
    loud = sensor.master.raw("0!", break_first=True)
    control = sensor.master.raw("0!", break_first=True)
    assert not quiet.answered and loud.answered and control.answered
    return quiet, loud, control


def test_a_stalled_silent_probe_is_no_pass():
    quiet, _loud, control = _probes()
    found = silent("R-7.0-15", [quiet], "asleep", baseline=control, stalled=[STALL])
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail and "no command outside a stall" in found.detail
    plain = silent("R-7.0-15", [quiet], "asleep", baseline=control)
    assert plain.verdict is Verdict.PASS  # the control: the same silence outside any stall


def test_a_stalled_answer_is_no_fail():
    _quiet, loud, control = _probes()
    found = silent("R-7.0-14", [loud], "asleep", baseline=control, stalled=[STALL])
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail and "0<CR><LF>" in found.detail
    plain = silent("R-7.0-14", [loud], "asleep", baseline=control, stalled=[None])
    assert plain.verdict is Verdict.FAIL


def test_a_probe_outside_any_stall_decides_beside_a_stalled_one():
    quiet, loud, control = _probes()
    answered = silent("R-7.0-15", [quiet, loud], "asleep", baseline=control, stalled=[STALL, None])
    assert answered.verdict is Verdict.FAIL  # the unstalled answer stands
    heard = silent("R-7.0-15", [loud, quiet], "asleep", baseline=control, stalled=[STALL, None])
    assert heard.verdict is Verdict.PASS and heard.observed == 1, heard.detail
    assert WHY in heard.detail  # the stalled one named as set aside


def test_held_by_either_way_holds_a_pass_too():
    ok = passed("R-7.0-14", "stayed silent", observed=1)
    assert held_by(ok, STALL).verdict is Verdict.PASS  # a violation's holder, as before
    held = held_by(ok, STALL, either_way=True)
    assert held.verdict is Verdict.INCONCLUSIVE and WHY in held.detail
    assert held_by(ok, None, either_way=True).verdict is Verdict.PASS
    bad = failed("R-7.0-14", "answered", observed=1)
    assert held_by(bad, STALL, either_way=True).verdict is Verdict.INCONCLUSIVE


def _band_gap(stalled: bool, gap: float = 1.9e-3) -> Run:
    """D1's reply with ``gap`` before its fourth character (1.9 ms: inside the 1.66..2.06 ms
    band, where R-7.0-01 grants no tolerance), the NOTE of a stall after it if asked."""
    run = Run()
    run.exchange("0D0!", "0+1.50+2.25\r\n")
    run.exchange("0D1!", "0+3.50+4.25\r\n", gap=gap, at=4, stalled=stalled)
    return run


def test_a_band_gap_across_a_stall_is_inconclusive():
    stamps = StampUncertainty(1e-4)
    found = _band_gap(True).findings(wire.judge_gaps, stamps)["R-7.0-01"]
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert WHY in found.detail and "relies on the ±0.40 ms" in found.detail
    plain = _band_gap(True).findings(wire.judge_gaps, stamps, noted=False)["R-7.0-01"]
    assert plain.verdict is Verdict.FAIL and WHY not in plain.detail


def test_a_recorded_band_gap_across_a_stall_is_inconclusive():
    """What a recording of the paused run is judged by (the sensor pass's gaps)."""
    found = {f.requirement: f for f in _band_gap(True).recorded().gaps}["R-7.0-01"]
    assert found.verdict is Verdict.INCONCLUSIVE and WHY in found.detail, found.detail
    plain = {f.requirement: f for f in _band_gap(True).recorded(noted=False).gaps}
    assert plain["R-7.0-01"].verdict is Verdict.FAIL


def test_a_long_gap_across_a_stall_is_still_r_7_0_12_s_alone():
    """A 120 ms gap is past the band: R-7.0-01 PASSes on it, stalled or not."""
    stamps = StampUncertainty(1e-4)
    found = _band_gap(True, gap=0.120).findings(wire.judge_gaps, stamps)["R-7.0-01"]
    assert found.verdict is Verdict.PASS, found.detail


def _exchange(text: str, reply: str, t: float, stray: list[Event] | None = None) -> Exchange:
    brk = Event(EventKind.BREAK, TOOL, t, t + 0.0125, uncertainty=U)
    cmd = chars(TOOL, text, t + 0.0215, uncertainty=U)
    rep = chars(DUT, reply, cmd[-1].end + 0.009, uncertainty=U)
    attempt = Attempt(brk, cmd, rep, OK, rep[-1].end + 0.01, stray_events=stray or [])
    return Exchange(parse_command(text), text, [attempt])


def _engine_wait(note_at: float | None) -> Measurement:
    """The engine's record of 0M! (ttt 1 s) whose service request the stall delivered past
    the wait's deadline: queued, read as D0's stray characters, the wait empty; the NOTE
    (written as the reader resumed, before the engine's break for D0) at ``note_at`` s
    past the reply."""
    start = _exchange("0M!", "00012\r\n", 0.0)
    reply_end = start.attempts[0].reply_events[-1].end
    m = Measurement(parse_command("0M!"), start, ttt=1, count=2, reply_end=reply_end)
    request = chars(DUT, "0\r\n", reply_end + 1.225, uncertainty=U)
    m.data = [_exchange("0D0!", "0+1+2\r\n", request[-1].end + 0.03, request)]
    m.values = ["+1", "+2"]
    notes = []
    if note_at is not None:
        at = reply_end + note_at
        notes = [Event(EventKind.NOTE, TOOL, at, at, text=host_stall.note_text(0.15))]
    mark_waits([m], host_stall.stalls(notes))
    return m


def test_a_request_missed_across_the_wait_s_deadline_is_not_the_sensor_s():
    (found,) = judge.judge([_engine_wait(1.25)], ["R-4.4.6-02"], "14")
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "no service request" in found.detail and WHY in found.detail


def test_the_same_missed_request_outside_any_stall_fails():
    for note_at in (None, 0.4):  # no stall, or one early in the wait, before ttt
        (found,) = judge.judge([_engine_wait(note_at)], ["R-4.4.6-02"], "14")
        assert found.verdict is Verdict.FAIL, (note_at, found.detail)
