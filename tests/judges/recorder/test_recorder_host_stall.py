"""Recorder judges over hand-built transcripts with a NOTE of the tool's own host stalling
(truth32): a deviation whose decisive interval a noted stall covers is INCONCLUSIVE naming
the stall; the same deviation with the stall elsewhere still FAILs, a clean exchange under a
stall still PASSes.

A stall note (``host_stall.note_text``) at t covers ``t - ms - 50 ms .. t + 30 ms``; the
served line writes it when its thread comes back late, a listening link when its reader
does."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from conformance.judges.recorder.breaks import judge_break_rules, judge_breaks
from conformance.judges.recorder.collection import judge_data_collection, judge_high_volume
from conformance.judges.recorder.commands import judge_character_gaps, judge_command_text
from conformance.judges.recorder.measurements import observed_measurements
from conformance.judges.recorder.retries import judge_retries
from conformance.judges.recorder.waits import judge_measure_waits
from conformance.links.host_stall import note_text
from conformance.offline.recorder_windows import judge_views
from conformance.protocol.crc import ascii_crc
from conformance.transcript import TOOL, Event, EventKind
from conformance.verdicts import Finding, Verdict
from conformance.view.segments import merge_views

from .test_recorder_judges import Wire, by_id

STALLED = "the tool's host stalled"


class Stalling(Wire):
    """:class:`Wire` that can note a stall of the tool's host where it stands."""

    def stall(self, ms: float = 120.0, at: float | None = None) -> Stalling:
        t = self.t if at is None else at
        self.events.append(Event(EventKind.NOTE, TOOL, t, t, text=note_text(ms / 1e3)))
        return self


def _held(found: Finding) -> None:
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert STALLED in found.detail


def _far(w: Stalling) -> Stalling:
    """The same recording with its stall noted 5 s after everything (no interval near it)."""
    return w.idle(5000).stall()


# -- command characters: R-7.0-13, R-7.0-01, R-4.4-04 ----------------------------------------


def _gap_in_command(gap_ms: float, stalled: bool) -> Stalling:
    w = Stalling().brk().rec("0M").idle(gap_ms)
    if stalled:
        w.stall(max(gap_ms, 40.0))  # noted after the burst that came in late
    w.rec("!").sensor("00011\r\n")
    return w if stalled else _far(w)


def test_a_gap_inside_a_command_across_a_stall_is_held_r_7_0_13():
    _held(by_id(judge_character_gaps(_gap_in_command(3.0, True).view(), 0.0))["R-7.0-13"])
    far = by_id(judge_character_gaps(_gap_in_command(3.0, False).view(), 0.0))
    assert far["R-7.0-13"].verdict is Verdict.FAIL


def test_a_gap_in_the_tolerance_band_across_a_stall_is_held_r_7_0_01():
    stalled = by_id(judge_character_gaps(_gap_in_command(1.9, True).view(), 0.0))
    _held(stalled["R-7.0-01"])
    _held(stalled["R-7.0-13"])
    far = by_id(judge_character_gaps(_gap_in_command(1.9, False).view(), 0.0))
    assert far["R-7.0-01"].verdict is far["R-7.0-13"].verdict is Verdict.FAIL


def test_one_gap_outside_every_stall_still_fails_beside_a_held_one_r_7_0_13_r_7_0_01():
    w = _gap_in_command(1.9, True).idle(30).brk().rec("0I", gap_ms=0.0).idle(1.9).rec("!")
    found = by_id(judge_character_gaps(w.view(), 0.0))
    assert found["R-7.0-01"].verdict is found["R-7.0-13"].verdict is Verdict.FAIL
    assert STALLED not in found["R-7.0-01"].detail


def test_a_command_part_dropped_at_a_gap_across_a_stall_is_held_r_4_4_04():
    """An in-process recorder paused after '0M' (the tool's process, the recorder with it):
    150 ms of marking before its '!' is the host's doing."""
    _held(by_id(judge_command_text(_gap_in_command(150.0, True).view(), 0.0))["R-4.4-04"])
    far = by_id(judge_command_text(_gap_in_command(150.0, False).view(), 0.0))
    assert far["R-4.4-04"].verdict is Verdict.FAIL


def test_clean_commands_under_a_stall_still_pass():
    w = Stalling().brk().rec("0M!").stall(80).sensor("00011\r\n").idle(30).rec("0M!")
    found = {**by_id(judge_character_gaps(w.view(), 0.0)), **by_id(judge_command_text(w.view()))}
    for rid in ("R-7.0-13", "R-7.0-01", "R-4.4-04", "R-4.3-01"):
        assert found[rid].verdict is Verdict.PASS, (rid, found[rid].detail)


# -- breaks: R-7.0-02, R-7.0-06 ----------------------------------------------------------------


def test_a_short_break_across_a_stall_is_held_r_7_0_02():
    stalled = Stalling().brk(10.0).stall(100).rec("0!").sensor("0\r\n")
    _held(by_id(judge_breaks(stalled.view(), 0.0))["R-7.0-02"])
    far = _far(Stalling().brk(10.0).rec("0!").sensor("0\r\n"))
    assert by_id(judge_breaks(far.view(), 0.0))["R-7.0-02"].verdict is Verdict.FAIL


def test_a_short_marking_after_a_break_across_a_stall_is_held_r_7_0_06():
    stalled = Stalling().brk(13.0, 5.0).stall(100).rec("0!").sensor("0\r\n")
    _held(by_id(judge_breaks(stalled.view(), 0.0))["R-7.0-06"])
    far = _far(Stalling().brk(13.0, 5.0).rec("0!").sensor("0\r\n"))
    assert by_id(judge_breaks(far.view(), 0.0))["R-7.0-06"].verdict is Verdict.FAIL
    clean = Stalling().brk().stall(100).rec("0!").sensor("0\r\n")
    assert {f.verdict for f in judge_breaks(clean.view(), 0.0)} == {Verdict.PASS}


# -- break rules: R-7.0-17, R-7.1-01 -----------------------------------------------------------


def test_marking_before_a_command_without_a_break_across_a_stall_is_held_r_7_0_17():
    """base-s68 under pauses (in-process golden recorder): "164.02 ms ... before 0M!"."""
    w = Stalling().brk().rec("0!").sensor("0\r\n").idle(164).stall(120).rec("0M!")
    _held(by_id(judge_break_rules(w.view(), 0.0))["R-7.0-17"])
    far = _far(Stalling().brk().rec("0!").sensor("0\r\n").idle(164).rec("0M!"))
    found = by_id(judge_break_rules(far.view(), 0.0))["R-7.0-17"]
    assert found.verdict is Verdict.FAIL and found.measured_ms == 164.0
    # a new sensor addressed without a break is no interval: the stall excuses nothing
    new = Stalling().brk().rec("0!").sensor("0\r\n").idle(20).stall(40).rec("1!")
    assert by_id(judge_break_rules(new.view(), 0.0))["R-7.0-17"].verdict is Verdict.FAIL
    clean = Stalling().brk().rec("0!").sensor("0\r\n").idle(20).stall(40).rec("0I!")
    assert by_id(judge_break_rules(clean.view(), 0.0))["R-7.0-17"].verdict is Verdict.PASS


def test_a_break_laid_with_no_length_across_a_stall_is_held_r_7_0_17():
    """truth32's paused run (a recorder outside the tool): the stall held back the
    recorder's retries, its break and its next command, which came in one late read; the
    break was laid 0.00 ms long, too short to be one, and R-7.0-17 FAILed "no break before
    5A0!, a new sensor". A break is no gap in the stamps: none at all still FAILs."""
    w = Stalling().brk().rec("0A5!").idle(20).brk(0.0, 9.0).stall(180).rec("5A0!")
    found = by_id(judge_break_rules(w.view(), 0.0))["R-7.0-17"]
    _held(found)
    assert "too short to be a break" in found.detail
    far = _far(Stalling().brk().rec("0A5!").idle(20).brk(0.0, 9.0).rec("5A0!"))
    assert by_id(judge_break_rules(far.view(), 0.0))["R-7.0-17"].verdict is Verdict.FAIL


def _after_service_request(stalled: bool) -> Stalling:
    w = Stalling().brk().rec("0M!").sensor("00011\r\n").sensor("0\r\n", delay_ms=600)
    w.idle(120)
    if stalled:
        w.stall(110)
    w.rec("0D0!").sensor("0+1\r\n")
    return w if stalled else _far(w)


def test_d0_without_a_break_after_the_service_request_across_a_stall_is_held_r_7_1_01():
    _held(by_id(judge_break_rules(_after_service_request(True).view(), 0.0))["R-7.1-01"])
    far = by_id(judge_break_rules(_after_service_request(False).view(), 0.0))["R-7.1-01"]
    assert far.verdict is Verdict.FAIL


# -- retries: R-7.2-02, R-7.2-03, R-7.2-06 ----------------------------------------------------


def test_a_retry_timed_across_a_stall_is_held_r_7_2_02():
    late = Stalling().brk().rec("0!").idle(120).stall(100).rec("0!").sensor("0\r\n")
    _held(by_id(judge_retries(late.view(), 0.0))["R-7.2-02"])
    far = _far(Stalling().brk().rec("0!").idle(12).rec("0!").sensor("0\r\n"))
    assert by_id(judge_retries(far.view(), 0.0))["R-7.2-02"].verdict is Verdict.FAIL
    clean = Stalling().brk().rec("0!").idle(45).stall(30).rec("0!").sensor("0\r\n")
    found = by_id(judge_retries(clean.view(), 0.0))
    assert found["R-7.2-02"].verdict is found["R-7.2-01"].verdict is Verdict.PASS


def test_no_retry_after_a_reply_a_stall_held_back_is_held_r_7_2_02_r_7_2_03():
    """base-s68 under pauses: "no retry without a break after no reply to 0D2!: sent again
    only after a new break, 0.034 s later" and "0D0! sequence 1: 1 retries, then no more"."""
    w = Stalling().brk().rec("0D2!").idle(60).stall(150).brk().rec("0D2!").sensor("0+1\r\n")
    _held(by_id(judge_retries(w.view(), 0.0))["R-7.2-02"])
    far = _far(Stalling().brk().rec("0D2!").idle(60).brk().rec("0D2!").sensor("0+1\r\n"))
    assert by_id(judge_retries(far.view(), 0.0))["R-7.2-02"].verdict is Verdict.FAIL
    gave_up = Stalling().brk().rec("0!").idle(45).rec("0!").stall(150).idle(300)
    _held(by_id(judge_retries(gave_up.view(), 0.0))["R-7.2-03"])
    far = _far(Stalling().brk().rec("0!").idle(45).rec("0!").idle(300))
    assert by_id(judge_retries(far.view(), 0.0))["R-7.2-03"].verdict is Verdict.FAIL


def _talked_over(stalled: bool) -> Stalling:
    w = Stalling().brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n", parity=False)
    w.t -= 30e-3  # the retry starts while the last characters are still coming
    if stalled:
        w.stall(100)
    w.rec("0D0!").sensor("0+1.5+2.5+3.5\r\n")
    return w if stalled else _far(w)


def test_a_retry_over_an_invalid_reply_across_a_stall_is_held_r_7_2_06():
    _held(by_id(judge_retries(_talked_over(True).view(), 0.0))["R-7.2-06"])
    far = by_id(judge_retries(_talked_over(False).view(), 0.0))["R-7.2-06"]
    assert far.verdict is Verdict.FAIL


def _cut_reply(stalled: bool) -> Stalling:
    """base-s68 under pauses: "the recorder's break at t=99.663 s cut into the reply '0002'
    ..., and sent 0M2! again after it"."""
    w = Stalling().brk().rec("0M2!").sensor("0002")
    if stalled:
        w.stall(120)
    w.brk().rec("0M2!").sensor("00023\r\n")
    return w if stalled else _far(w)


def test_a_break_over_a_reply_a_stall_held_back_is_held_r_7_2_06():
    _held(by_id(judge_retries(_cut_reply(True).view(), 0.0))["R-7.2-06"])
    far = by_id(judge_retries(_cut_reply(False).view(), 0.0))["R-7.2-06"]
    assert far.verdict is Verdict.FAIL, far.detail


# -- the view and the windowed (passive) path ------------------------------------------------


def test_the_view_reads_the_stall_notes_and_a_merged_view_keeps_them():
    a = Stalling().brk().rec("0!").stall(90).view()
    b = Stalling().brk().rec("1!").view()
    assert len(a.stalls) == 1 and not b.stalls
    assert merge_views([a, b]).stalls == a.stalls
    assert a.stalled_over(0.0, 0.01) is a.stalls[0]
    assert b.stalled_over(0.0, 1.0) is None


def test_the_passive_folds_read_the_recordings_stalls():
    """A window's view holds no notes: the recording's stalls go to the folds."""
    from conformance.judges.recorder.commands import CharacterGaps
    from conformance.links.host_stall import stalls
    from conformance.view.segments import read_view

    events = _gap_in_command(3.0, True).events
    plain = [e for e in events if e.kind is not EventKind.NOTE]
    noted = stalls(events)
    held = judge_views([read_view(plain)], 0.0, noted)
    _held(by_id(held.character_gaps)["R-7.0-13"])
    bare = judge_views([read_view(plain)], 0.0)
    assert by_id(bare.character_gaps)["R-7.0-13"].verdict is Verdict.FAIL
    fold = CharacterGaps(0.0, noted)
    fold.add(read_view(plain))
    _held(by_id(fold.findings())["R-7.0-13"])


# -- the served line's whole-run guard ---------------------------------------------------------


def _guarded(unexplained: float) -> list[Finding]:
    from conformance.run import ConformanceRun

    findings = [
        Finding("R-7.0-02", Verdict.FAIL, "break length: 10.00 ms", evidence=["b"], observed=1),
        Finding("R-4.4-02", Verdict.FAIL, "logged 3 of 4 values", evidence=["l"], observed=1),
    ]
    session = SimpleNamespace(
        worst_lateness=lambda: 0.150,
        unexplained_lateness=lambda: unexplained,
        noted_stalls=lambda: [],
        recorder_in_process=lambda: False,  # its own process: the stalls are the tool's
    )
    # a case that names no scenario slice: held wherever the line was late (truth34)
    run = SimpleNamespace(session=session, cases=[SimpleNamespace(findings=findings, evidence=[])])
    ConformanceRun._guard_served_line(run)  # type: ignore[arg-type]
    return findings


def test_the_guard_leaves_the_stall_reading_rules_where_the_notes_explain_the_lateness():
    """Every late frame inside a noted stall: R-7.0-02's judge held what the stalls covered,
    so its FAIL stands; a rule whose judge reads no stall is undecided as before."""
    kept, other = _guarded(0.0)
    assert kept.verdict is Verdict.FAIL
    assert other.verdict is Verdict.INCONCLUSIVE and "fell 150.0 ms behind" in other.detail


def test_the_guard_undecides_every_rule_where_lateness_no_note_explains():
    for f in _guarded(0.010):
        assert f.verdict is Verdict.INCONCLUSIVE


@pytest.mark.parametrize("late", [0.0, 0.001])
def test_the_guard_leaves_a_line_that_kept_time(late: float):
    from conformance.run import ConformanceRun

    f = Finding("R-4.4-02", Verdict.FAIL, "x", evidence=["l"], observed=1)
    session = SimpleNamespace(worst_lateness=lambda: late, unexplained_lateness=lambda: late)
    run = SimpleNamespace(session=session, cases=[SimpleNamespace(findings=[f])])
    ConformanceRun._guard_served_line(run)  # type: ignore[arg-type]
    assert f.verdict is Verdict.FAIL


# -- what a stall can account for --------------------------------------------------------------


def test_marking_longer_than_the_stalls_inside_it_can_explain_still_fails_r_7_0_17():
    """no-break-after-87ms under the pauses: aD0! without a break 2 s after ttt, with a
    stall of 150 ms (and its reach) inside those 2 s: the recorder's own 1.8 s stand."""
    w = Stalling().brk().rec("0!").sensor("0\r\n").idle(1000).stall(150).idle(1000).rec("0D0!")
    found = by_id(judge_break_rules(w.view(), 0.0))["R-7.0-17"]
    assert found.verdict is Verdict.FAIL and STALLED not in found.detail
    # the same with stalls that add up to what can stretch 300 ms to over 87 ms: held
    w = Stalling().brk().rec("0!").sensor("0\r\n").idle(150).stall(150).idle(150).stall(150)
    _held(by_id(judge_break_rules(w.rec("0I!").view(), 0.0))["R-7.0-17"])


def test_a_command_part_dropped_longer_than_a_stall_can_explain_still_fails_r_4_4_04():
    w = Stalling().brk().rec("0M").idle(1000).stall(150).idle(1000).rec("!")
    found = by_id(judge_command_text(w.view(), 0.0))["R-4.4-04"]
    assert found.verdict is Verdict.FAIL and STALLED not in found.detail


def _asleep(stalled: bool) -> Stalling:
    """truth32's paused run, in-process golden recorder: the reply to 0D1! ended, the tool's
    process (the recorder with it) stalled 130 ms, 0D2! went 136 ms later without a break to
    a sensor gone to standby, no reply, then a break and 0D2! again."""
    w = Stalling().brk().rec("0D1!").sensor("0+1\r\n").idle(98)
    if stalled:
        w.stall(130)
    w.idle(38).rec("0D2!").idle(35).brk().rec("0D2!").sensor("0+2\r\n")
    return w if stalled else _far(w)


def test_no_retry_to_a_try_a_stall_sent_to_a_sleeping_sensor_is_held_r_7_2_02_r_7_2_03():
    found = by_id(judge_retries(_asleep(True).view(), 0.0))
    _held(found["R-7.2-02"])
    _held(found["R-7.2-03"])
    far = by_id(judge_retries(_asleep(False).view(), 0.0))
    assert far["R-7.2-02"].verdict is far["R-7.2-03"].verdict is Verdict.FAIL


# -- the wait for data: R-4.4.5-05 -------------------------------------------------------------


def _measure_tried_again(stalled: bool, reply_ms: float = 150.0) -> Stalling:
    """truth32's paused clean run (in-process golden recorder): the played sensor's reply to
    0M! went out ``reply_ms`` late, the recorder had given up on it and sent 0M! again with a
    break over it; the first 0M! read "no aD0! after the measurement"."""
    w = Stalling().brk().rec("0M!").sensor("00023\r\n", delay_ms=reply_ms)
    if stalled:
        w.stall(160)
    w.brk().rec("0M!").sensor("00023\r\n").sensor("0\r\n", delay_ms=300)
    w.idle(9).rec("0D0!").sensor("0+1+2+3\r\n")
    return w if stalled else _far(w)


def _waits(w: Stalling) -> dict[str, Finding]:
    view = w.view()
    return by_id(judge_measure_waits(observed_measurements(view, 0.0), 0.0, view.stalls))


def test_a_measurement_tried_again_across_a_stall_is_held_r_4_4_5_05():
    found = _waits(_measure_tried_again(True))["R-4.4.5-05"]
    _held(found)
    assert "no aD0! after the measurement" in found.detail
    assert _waits(_measure_tried_again(False))["R-4.4.5-05"].verdict is Verdict.FAIL
    # without the stalls given, judged as before
    view = _measure_tried_again(True).view()
    plain = by_id(judge_measure_waits(observed_measurements(view, 0.0), 0.0))["R-4.4.5-05"]
    assert plain.verdict is Verdict.FAIL


def test_a_measurement_sent_again_long_after_a_stall_still_fails_r_4_4_5_05():
    """The same command again 2 s after the stall over its reply is the recorder's doing."""
    w = Stalling().brk().rec("0M!").sensor("00023\r\n").stall(120).idle(2000)
    w.brk().rec("0M!").sensor("00023\r\n").sensor("0\r\n", delay_ms=300)
    w.idle(9).rec("0D0!").sensor("0+1+2+3\r\n")
    assert _waits(w)["R-4.4.5-05"].verdict is Verdict.FAIL
    assert _collection(w).verdict is Verdict.FAIL


def test_a_measurement_given_up_for_another_command_across_a_stall_still_fails_r_4_4_5_05():
    """A recorder that turns to another command after the reply (no new try of the
    measurement) is not excused by a stall: nothing it did waited on a late reply."""
    w = Stalling().brk().rec("0M!").sensor("00023\r\n").stall(120)
    w.idle(50).brk().rec("0I!").sensor("013CONFORM EMU001 1.0\r\n")
    assert _waits(w)["R-4.4.5-05"].verdict is Verdict.FAIL


def test_a_missing_break_after_ttt_across_a_stall_still_fails_r_4_4_5_05():
    """aD0! after ttt without a break is the recorder's choice, which a stall does not make
    (truth32's faulty runs, ``no-break-after-87ms``: R-4.4.5-05 FAILed there and still does)."""
    w = Stalling().brk().rec("0M!").sensor("00013\r\n").idle(1000).stall(120).idle(10)
    w.rec("0D0!").sensor("0+1+2+3\r\n")
    found = _waits(w)["R-4.4.5-05"]
    assert found.verdict is Verdict.FAIL and "without a break" in found.detail


# -- data collection: R-4.4.8-05 ---------------------------------------------------------------


def _collection(w: Stalling) -> Finding:
    view = w.view()
    return by_id(judge_data_collection(observed_measurements(view, 0.0), view.stalls))["R-4.4.8-05"]


def test_a_measurement_tried_again_across_a_stall_is_held_r_4_4_8_05():
    """The same run: R-4.4.8-05 read "0M!: stopped after the reply with 0 of 3 values"."""
    found = _collection(_measure_tried_again(True))
    _held(found)
    assert "stopped after the reply with 0 of 3 values" in found.detail
    assert _collection(_measure_tried_again(False)).verdict is Verdict.FAIL


def _stopped_short(stalled: bool) -> Stalling:
    """0M2! (9 values), D0 and D1 read, then another command: "stopped after 0D1! with
    6 of 9 values". Stalled: D1's reply came in across a noted stall (truth32's paused clean
    run: D1's and D2's replies met the recorder's retries, the recorder logged all 9)."""
    w = Stalling().brk().rec("0M2!").sensor("00029\r\n").sensor("0\r\n", delay_ms=300)
    w.idle(9).rec("0D0!").sensor("0+1+2+3\r\n").idle(9).rec("0D1!")
    w.sensor("0+4+5+6\r\n", delay_ms=150 if stalled else 9.0)
    if stalled:
        w.stall(140)
    w.idle(100).brk().rec("0I!").sensor("013CONFORM EMU001 1.0\r\n")
    return w if stalled else _far(w)


def test_a_collection_stopped_short_across_a_stall_is_held_r_4_4_8_05():
    found = _collection(_stopped_short(True))
    _held(found)
    assert "stopped after 0D1! with 6 of 9 values" in found.detail
    assert _collection(_stopped_short(False)).verdict is Verdict.FAIL


def test_a_collection_stopped_short_with_the_stall_before_it_still_fails_r_4_4_8_05():
    """A stall over the measurement's reply, before its data were asked for, says nothing
    of the values counted: stopping short is the recorder's doing."""
    w = Stalling().brk().rec("0M2!").sensor("00029\r\n").stall(80)
    w.sensor("0\r\n", delay_ms=300).idle(9).rec("0D0!").sensor("0+1+2+3\r\n")
    w.idle(100).brk().rec("0I!").sensor("013CONFORM EMU001 1.0\r\n")
    assert _collection(w).verdict is Verdict.FAIL


def test_the_passive_findings_carry_the_recordings_stalls():
    """The passive measurement cases read them from :func:`recorder_findings`."""
    w = _measure_tried_again(True)
    found = judge_views([w.view()], 0.0, w.view().stalls)
    assert found.stalls == tuple(w.view().stalls) and len(found.stalls) == 1


# -- high-volume collection: R-5.1-04 ----------------------------------------------------------


def _high_volume_short(stalled: bool) -> Stalling:
    """0HA! (33 values), D0 read, its D1's reply across a noted stall, then another
    command: "stopped at 0D1! with 6 of 33 values" (truth32's paused runs: "0HA!: stopped at
    0D0! with 8 of 120 values", its replies met by the recorder's retries)."""
    w = Stalling().brk().rec("0HA!").sensor("0002033\r\n").idle(2100).brk().rec("0D0!")
    w.sensor(f"{_crc('0+1+2+3')}\r\n").idle(9).rec("0D1!").sensor(f"{_crc('0+4+5+6')}\r\n")
    if stalled:
        w.stall(140)
    w.idle(100).brk().rec("0I!").sensor("013CONFORM EMU001 1.0\r\n")
    return w if stalled else _far(w)


def _crc(text: str) -> str:
    return text + ascii_crc(text)


def test_a_high_volume_collection_stopped_short_across_a_stall_is_held_r_5_1_04():
    def judged(w: Stalling) -> Finding:
        view = w.view()
        taken = observed_measurements(view, 0.0)
        return by_id(judge_high_volume(taken, True, stalls=view.stalls))["R-5.1-04"]

    found = judged(_high_volume_short(True))
    _held(found)
    assert "with 6 of 33 values" in found.detail
    assert judged(_high_volume_short(False)).verdict is Verdict.FAIL
