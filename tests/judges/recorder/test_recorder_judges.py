"""Recorder judges on hand-made transcripts: each rule passes a conforming exchange and fails
the deviation it exists for (a judge that cannot fail is a defect)."""

from __future__ import annotations

from conformance.judges.recorder.breaks import judge_break_rules, judge_breaks
from conformance.judges.recorder.capabilities import (
    judge_addresses,
    judge_commands_issued,
    judge_multiline_end,
    judge_transparent,
)
from conformance.judges.recorder.collection import (
    judge_concurrent_storage,
    judge_data_collection,
    judge_high_volume,
)
from conformance.judges.recorder.commands import judge_character_gaps, judge_command_text
from conformance.judges.recorder.measurements import observed_measurements
from conformance.judges.recorder.retries import judge_crc_checked, judge_retries
from conformance.judges.recorder.waits import judge_measure_waits
from conformance.protocol.crc import ascii_crc
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.segments import TranscriptView, read_view


class Wire:
    """Builds a transcript: the recorder's side has origin ``tool`` (as on the sim bus)."""

    def __init__(self) -> None:
        self.events: list[Event] = []
        self.t = 0.0

    def brk(self, ms: float = 13.0, marking_ms: float = 9.0) -> Wire:
        self.events.append(Event(EventKind.BREAK, TOOL, self.t, self.t + ms / 1e3))
        self.t += (ms + marking_ms) / 1e3
        return self

    def chars(self, text: str, origin: str, gap_ms: float = 0.0, parity: bool = True) -> Wire:
        for c in text:
            wire = to_wire_7e1(ord(c)) ^ (0 if parity else 0x80)
            self.events.append(Event(EventKind.CHAR, origin, self.t, self.t + CHAR_TIME, wire))
            self.t += CHAR_TIME + gap_ms / 1e3
        self.t -= gap_ms / 1e3
        return self

    def rec(self, text: str, gap_ms: float = 0.0) -> Wire:
        return self.chars(text, TOOL, gap_ms)

    def sensor(self, text: str, delay_ms: float = 9.0, origin: str = "sensor0", **kw) -> Wire:
        self.t += delay_ms / 1e3
        return self.chars(text, origin, **kw)

    def idle(self, ms: float) -> Wire:
        self.t += ms / 1e3
        return self

    def view(self) -> TranscriptView:
        return read_view(self.events)


def by_id(findings):
    return {f.requirement: f for f in findings}


def test_breaks_and_marking():
    good = Wire().brk().rec("0!").sensor("0\r\n").view()
    assert {f.verdict for f in judge_breaks(good, 0.0)} == {Verdict.PASS}
    short = by_id(judge_breaks(Wire().brk(10.0).rec("0!").view(), 0.0))
    assert short["R-7.0-02"].verdict is Verdict.FAIL
    assert short["R-7.0-02"].measured_ms == 10.0
    early = by_id(judge_breaks(Wire().brk(13.0, 5.0).rec("0!").view(), 0.0))
    assert early["R-7.0-06"].verdict is Verdict.FAIL
    # a 12 ms break stamped with ±1 ms cannot be told from an 11 ms one
    unsure = by_id(judge_breaks(Wire().brk(12.0).rec("0!").view(), 1e-3))
    assert unsure["R-7.0-02"].verdict is Verdict.INCONCLUSIVE


def test_command_text():
    found = by_id(judge_command_text(Wire().brk().rec("0M!").view()))
    assert {f.verdict for f in found.values()} == {Verdict.PASS}
    w = Wire().brk().rec("0M!!").idle(200).brk().rec("$M!").idle(200).brk().rec("0M")
    bad = by_id(judge_command_text(w.view()))
    assert bad["R-4.4-04"].verdict is Verdict.FAIL
    assert "0M!!" in bad["R-4.4-04"].detail and "0M:" in bad["R-4.4-04"].detail
    assert bad["R-4.3-01"].verdict is Verdict.FAIL
    ctrl = by_id(judge_command_text(Wire().brk().rec("0\x07!").view()))
    assert ctrl["R-4.2-01"].verdict is Verdict.FAIL


def test_address_query_with_a_nul_after_its_bang_is_addressed_r_4_3_01():
    """An STM32 HAL logger (HarveyBates/stm32-projects, twenty-sixth round) sends each
    command with the NUL that ends its C string: ``?!<NUL>``. The NUL is R-4.2-01's and
    R-4.4-04's FAIL; R-4.3-01 FAILed "starts with ?, not an address" on the query's
    wildcard. A '?' that is not ``?!`` still FAILs R-4.3-01, with or without the NUL."""
    query = by_id(judge_command_text(Wire().brk().rec("?!\x00").view()))
    assert query["R-4.2-01"].verdict is query["R-4.4-04"].verdict is Verdict.FAIL
    assert query["R-4.3-01"].verdict is Verdict.PASS, query["R-4.3-01"].detail
    for text in ("?M!\x00", "?M!", "?\x00!"):
        wild = by_id(judge_command_text(Wire().brk().rec(text).view()))
        assert wild["R-4.3-01"].verdict is Verdict.FAIL, text


def test_character_gaps_have_no_tolerance():
    ok = by_id(judge_character_gaps(Wire().brk().rec("0M!", gap_ms=1.5).view(), 0.0))
    assert ok["R-7.0-13"].verdict is ok["R-7.0-01"].verdict is Verdict.PASS
    lean = by_id(judge_character_gaps(Wire().brk().rec("0M!", gap_ms=1.9).view(), 0.0))
    assert lean["R-7.0-13"].verdict is lean["R-7.0-01"].verdict is Verdict.FAIL
    wide = by_id(judge_character_gaps(Wire().brk().rec("0M!", gap_ms=3.0).view(), 0.0))
    assert wide["R-7.0-13"].verdict is Verdict.FAIL
    assert wide["R-7.0-01"].verdict is Verdict.PASS


def test_unterminated_retries_are_not_one_command_R_7_0_13():
    """lixpaulian/dacq's sdi12_dr (nineteenth round) builds ``0M1`` with no ``!`` and retries
    it 50 ms later without a break: the wire shows ``0M1`` 50 ms ``0M1``. A sensor drops a
    partial command after 8.33 ms of marking (App. B), so the gap may be between two tries:
    R-7.0-13 cannot FAIL on it (it did: "50.00 ms in 0M10M1"), R-4.4-04 FAILs either way."""
    w = Wire().brk().rec("0M1").idle(50).rec("0M1").idle(50).rec("0M1")
    gaps = by_id(judge_character_gaps(w.view(), 0.0))
    assert gaps["R-7.0-13"].verdict is Verdict.INCONCLUSIVE
    assert "2 gap(s)" in gaps["R-7.0-13"].detail and "50.00 ms" in gaps["R-7.0-13"].detail
    assert by_id(judge_command_text(w.view()))["R-4.4-04"].verdict is Verdict.FAIL
    # a gap a sensor still holds the command over still FAILs, as does one after a '!'
    short = Wire().brk().rec("0M1").idle(7.5).rec("0M1")
    assert by_id(judge_character_gaps(short.view(), 0.0))["R-7.0-13"].verdict is Verdict.FAIL
    after = Wire().brk().rec("0M!").idle(2.0).rec("$")
    assert by_id(judge_character_gaps(after.view(), 0.0))["R-7.0-13"].verdict is Verdict.FAIL
    # the last try terminated: its text alone passes R-4.4-04, the tries before it do not
    ended = Wire().brk().rec("0M1").idle(50).rec("0M1").idle(50).rec("0MC!")
    assert by_id(judge_character_gaps(ended.view(), 0.0))["R-7.0-13"].verdict is (
        Verdict.INCONCLUSIVE
    )
    text = by_id(judge_command_text(ended.view()))["R-4.4-04"]
    assert text.verdict is Verdict.FAIL and "'0M1' then 50.00 ms" in text.detail, text.detail
    # a gap a sensor talked in is no marking (a retry the line held back behind a reply)
    held = Wire().brk().rec("0").sensor("0+1.0", delay_ms=0.0).rec("D0!").view()
    assert by_id(judge_character_gaps(held, 0.0))["R-7.0-13"].verdict is Verdict.FAIL
    assert by_id(judge_command_text(held))["R-4.4-04"].verdict is Verdict.PASS
    # a wait for '!' a sensor has dropped the command in: one of the two rules FAILs it
    bang = Wire().brk().rec("0M").idle(50).rec("!")
    assert by_id(judge_command_text(bang.view()))["R-4.4-04"].verdict is Verdict.FAIL
    # a gap judged elsewhere in the run wins over the undecided one
    both = Wire().brk().rec("0M!", gap_ms=3.0).idle(200).brk().rec("0M1").idle(50).rec("0M1")
    assert by_id(judge_character_gaps(both.view(), 0.0))["R-7.0-13"].verdict is Verdict.FAIL
    fine = Wire().brk().rec("0M!").idle(200).brk().rec("0M1").idle(50).rec("0M1")
    assert by_id(judge_character_gaps(fine.view(), 0.0))["R-7.0-13"].verdict is Verdict.INCONCLUSIVE


def test_a_new_address_right_after_a_bang_is_a_command_without_a_break_R_7_0_17_R_4_4_04():
    """A recorder that sends ``0M!`` and at once ``1M!`` sent two commands, each ending in
    its only '!' (4.4), the second to a new sensor with no break. Read as one transmission
    '0M!1M!', R-4.4-04 FAILed "'!' is not exactly the last character" and R-7.0-17 PASSed
    "all 2 commands were sent after a break" (a false PASS); the gap between them was judged
    as one inside a command (R-7.0-13)."""
    w = Wire().brk().rec("0M!1M!").idle(100).brk().rec("0!").sensor("0\r\n").view()
    assert by_id(judge_command_text(w))["R-4.4-04"].verdict is Verdict.PASS
    due = by_id(judge_break_rules(w, 0.0))["R-7.0-17"]
    assert due.verdict is Verdict.FAIL and "no break before 1M!" in due.detail, due.detail
    # a few ms of marking between them (under the 7.93 ms a new command needs): the same
    gapped = Wire().brk().rec("0M!").idle(3.0).rec("1M!").view()
    assert by_id(judge_break_rules(gapped, 0.0))["R-7.0-17"].verdict is Verdict.FAIL
    assert by_id(judge_character_gaps(gapped, 0.0))["R-7.0-13"].verdict is Verdict.PASS
    # a break between them: both conform, as before
    broken = Wire().brk().rec("0M!").idle(20).brk().rec("1M!").view()
    assert by_id(judge_break_rules(broken, 0.0))["R-7.0-17"].verdict is Verdict.PASS
    assert by_id(judge_command_text(broken))["R-4.4-04"].verdict is Verdict.PASS


def test_a_command_the_recorder_did_not_wait_on_is_no_unanswered_try_R_7_2_01():
    """``0M!`` and at once ``1M!``: the recorder never waited for 0M!'s reply (R-7.0-17
    FAILs the missing break), so there was no "no reply" to retry for; R-7.2-01 and
    R-7.2-05 FAILed "after no reply to 0M!: not sent again". 1M!, waited on and never
    answered nor sent again, still FAILs them; the same command at once is still a retry
    (R-7.2-02 FAILs its 0 ms)."""
    w = Wire().brk().rec("0M!1M!").idle(100).brk().rec("0!").sensor("0\r\n").view()
    found = by_id(judge_retries(w, 0.0))
    for rid in ("R-7.2-01", "R-7.2-05"):
        assert found[rid].verdict is Verdict.FAIL, found[rid].detail
        assert "0M!" not in found[rid].detail and "1M!" in found[rid].detail, found[rid].detail
    # a reply window left open (16 ms and more) before another command: 0M! unanswered as before
    waited = Wire().brk().rec("0M!").idle(16.0).rec("1M!").idle(100).brk().rec("0!").view()
    assert "0M!" in by_id(judge_retries(waited, 0.0))["R-7.2-01"].detail
    again = by_id(judge_retries(Wire().brk().rec("0M!0M!0M!").idle(100).view(), 0.0))
    assert again["R-7.2-02"].verdict is Verdict.FAIL and "0.00 ms" in again["R-7.2-02"].detail


def test_break_needed_for_a_new_address_and_after_87_ms():
    ok = Wire().brk().rec("0!").sensor("0\r\n").idle(20).rec("0I!").view()
    assert by_id(judge_break_rules(ok, 0.0))["R-7.0-17"].verdict is Verdict.PASS
    new = Wire().brk().rec("0!").sensor("0\r\n").idle(20).rec("1!").view()
    assert by_id(judge_break_rules(new, 0.0))["R-7.0-17"].verdict is Verdict.FAIL
    late = Wire().brk().rec("0!").sensor("0\r\n").idle(95).rec("0I!").view()
    found = by_id(judge_break_rules(late, 0.0))["R-7.0-17"]
    assert found.verdict is Verdict.FAIL and found.measured_ms == 95.0


def test_spacing_too_short_to_be_a_break_is_no_break_r_7_0_17():
    """An STM32 HAL logger (the thirtieth round's, docs/kit.md) sends its 'break' with the
    USART's send-break request: 10 low bits, 8.33 ms, then 1.67 ms of stop bits and the
    command. R-7.0-02 FAILed the length, but R-7.0-17 PASSed "all 11 commands were sent
    after a break" on spacing no sensor need take for one (its played sensors never woke).
    Spacing R-7.0-02 FAILs is no break here either; one whose length the stamps leave
    undecided (12 ms at +-1 ms) still counts, and a real break still PASSes."""
    short = Wire().brk(8.33, 1.67).rec("0M!").idle(200).brk(8.33, 1.67).rec("1M!").view()
    found = by_id(judge_break_rules(short, 0.0))["R-7.0-17"]
    assert found.verdict is Verdict.FAIL, found.detail
    assert "no break before 0M!" in found.detail and "too short to be a break" in found.detail
    # the same sensor after 200 ms: timed from the activity before the spacing, not after it
    again = Wire().brk().rec("0!").sensor("0\r\n").idle(200).brk(8.33, 1.67).rec("0I!").view()
    late = [f for f in judge_break_rules(again, 0.0) if f.requirement == "R-7.0-17"][0]
    assert late.verdict is Verdict.FAIL and "too short to be a break" in late.detail, late.detail
    unsure = Wire().brk(12.0).rec("0M!").view()
    assert by_id(judge_break_rules(unsure, 1e-3))["R-7.0-17"].verdict is Verdict.PASS
    real = Wire().brk(12.5, 8.5).rec("0M!").idle(200).brk(12.5, 8.5).rec("1M!").view()
    assert by_id(judge_break_rules(real, 0.0))["R-7.0-17"].verdict is Verdict.PASS


def _measurement(wire: Wire, address: str = "0", code: str = "M") -> Wire:
    wire.brk().rec(f"{address}{code}!")
    return wire.sensor(f"{address}0013\r\n", origin=f"sensor{address}")


def test_no_traffic_to_other_sensors_during_a_measurement():
    w = _measurement(Wire()).sensor("0\r\n", delay_ms=300).idle(9).rec("0D0!")
    w.sensor("0+1+2+3\r\n")
    taken = observed_measurements(w.view(), 0.0)
    assert by_id(judge_measure_waits(taken, 0.0))["R-4.4.5-06"].verdict is Verdict.PASS
    w = _measurement(Wire()).idle(100).brk().rec("1!").sensor("1\r\n", origin="sensor1")
    w.idle(400).brk().rec("0D0!").sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))
    assert found["R-4.4.5-06"].verdict is Verdict.FAIL
    # the recorder also took the line while the service request could still come
    assert found["R-4.4.5-07"].verdict is Verdict.FAIL


def test_a_first_data_command_past_d0_is_no_d0_r_4_4_5_05():
    """An STM32 HAL logger (HarveyBates/stm32-projects, twenty-sixth round) keeps its USART's
    pins swapped after a reply that filled its buffer, so its aD0! goes out on the other pin:
    the wire shows a bare break, then aD1!..aD8!. R-4.4.5-05 PASSed "aD0! within 0.5 s of the
    service request or ttt" on the aD1!; no aD0! was issued."""
    w = _measurement(Wire()).sensor("0\r\n", delay_ms=300).idle(9).brk().idle(30)
    w.brk().rec("0D1!").sensor("0\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))["R-4.4.5-05"]
    assert found.verdict is Verdict.FAIL, found.detail
    assert "0D1!, not aD0!" in found.detail
    # aD0! at the same moment: the reaction rule PASSes as before
    w = _measurement(Wire()).sensor("0\r\n", delay_ms=300).idle(9).brk().rec("0D0!")
    w.sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))["R-4.4.5-05"]
    assert found.verdict is Verdict.PASS, found.detail


def test_a_command_with_a_nul_after_its_bang_is_the_command_a_sensor_answers():
    """The same logger sends each command's C string with its NUL (``0M!<NUL>``); the played
    sensor answers at the ``!``, as a sensor does. The view took the text for no command: its
    measurements, retries and logged values went unjudged ("nothing was observed") or FAILed
    "logged, the command never sent". R-4.2-01 and R-4.4-04 still FAIL the NUL."""
    w = Wire().brk().rec("0M!\x00").sensor("00013\r\n", delay_ms=1.0)
    w.sensor("0\r\n", delay_ms=300).idle(9).rec("0D0!\x00").sensor("0+1+2+3\r\n", delay_ms=1.0)
    view = w.view()
    assert [s.stem for s in view.transmissions] == ["0M!", "0D0!"]
    taken = observed_measurements(view, 0.0)
    assert len(taken) == 1 and taken[0].values() == ["+1", "+2", "+3"]
    text = by_id(judge_command_text(view))
    assert text["R-4.2-01"].verdict is text["R-4.4-04"].verdict is Verdict.FAIL
    # a NUL before the '!' keeps the text whole: no command
    assert Wire().brk().rec("0M\x00!").view().transmissions[0].stem == "0M\x00!"


def test_d0_before_ttt_and_late_reaction():
    early = _measurement(Wire()).idle(500).brk().rec("0D0!").sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(early.view(), 0.0), 0.0))
    assert found["R-4.4.5-04"].verdict is Verdict.FAIL
    slow = _measurement(Wire()).sensor("0\r\n", delay_ms=300).idle(900)
    slow.brk().rec("0D0!").sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(slow.view(), 0.0), 0.0))
    assert found["R-4.4.5-04"].verdict is Verdict.PASS
    # 0.9 s after the service request: beyond the tool's 0.5 s, a figure the standard does
    # not give (decision T1), so a WARN that says so, not a FAIL
    late = found["R-4.4.5-05"]
    assert late.verdict is Verdict.WARN and late.decision == "T1"
    assert "0.5 s the tool allows" in late.detail and "decision T1" in late.detail
    # issue 20: aD0! 1.058 s after ttt (with its break) is a WARN too
    w = _measurement(Wire()).idle(1000 + 1058).brk().rec("0D0!").sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))
    assert found["R-4.4.5-05"].verdict is Verdict.WARN and "1.058 s after ttt" in (
        found["R-4.4.5-05"].detail
    )
    # without a break after ttt the recorder demonstrably did otherwise: still a FAIL
    w = _measurement(Wire()).idle(1010).rec("0D0!").sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))
    assert found["R-4.4.5-05"].verdict is Verdict.FAIL


def test_empty_reply_must_lead_to_the_measurement_again():
    w = _measurement(Wire()).idle(1100).brk().rec("0D0!").sensor("0\r\n").idle(9).rec("0I!")
    w.sensor("014CONFORM EMU001100\r\n")
    found = judge_data_collection(observed_measurements(w.view(), 0.0))
    assert found[0].verdict is Verdict.FAIL and "not issued again" in found[0].detail
    w = _measurement(Wire()).idle(1100).brk().rec("0D0!").sensor("0\r\n").idle(9).rec("0M!")
    w.sensor("00013\r\n").idle(1100).brk().rec("0D0!").sensor("0+1+2+3\r\n")
    assert judge_data_collection(observed_measurements(w.view(), 0.0))[0].verdict is Verdict.PASS


def test_an_empty_reply_read_past_fails_r_4_4_8_05_however_the_collection_ends():
    """HarveyBates/ESP32-SDI12 (docs/kit.md): after an empty D0 it asks D1, D2, ... up to D10,
    which gets no reply, and gives up: R-4.4.8-05 PASSed, the collection having ended on a
    problem (left to the retry rules) and the empty D0 before it not looked at."""
    w = _measurement(Wire()).idle(1100).brk().rec("0D0!").sensor("0\r\n").idle(9).brk()
    w.rec("0D1!").sensor("0\r\n").idle(9).brk().rec("0D2!").idle(1000)
    (found,) = judge_data_collection(observed_measurements(w.view(), 0.0))
    assert found.verdict is Verdict.FAIL, found.detail
    assert "0D0! came back empty" in found.detail and "read on, to 0D2!" in found.detail
    # ended on an unanswered D1 with no empty reply before it: still the retry rules'
    w = _measurement(Wire()).idle(1100).brk().rec("0D0!").sensor("0+1\r\n").idle(9).brk()
    w.rec("0D1!").idle(1000)
    (found,) = judge_data_collection(observed_measurements(w.view(), 0.0))
    assert found.verdict is not Verdict.FAIL, found.detail


def test_retry_windows_and_waiting_for_the_invalid_reply():
    early = Wire().brk().rec("0!").idle(12).rec("0!").sensor("0\r\n").view()
    assert by_id(judge_retries(early, 0.0))["R-7.2-02"].verdict is Verdict.FAIL
    good = Wire().brk().rec("0!").idle(45).rec("0!").sensor("0\r\n").view()
    found = by_id(judge_retries(good, 0.0))
    assert found["R-7.2-02"].verdict is found["R-7.2-01"].verdict is Verdict.PASS
    # a long reply with a parity error; the retry starts before that reply ended
    w = Wire().brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n", parity=False)
    w.t -= 30e-3  # the retry starts while the last characters are still coming
    talked_over = w.rec("0D0!").sensor("0+1.5+2.5+3.5\r\n").view()
    assert by_id(judge_retries(talked_over, 0.0))["R-7.2-06"].verdict is Verdict.FAIL
    w = Wire().brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n", parity=False).idle(25)
    waited = w.rec("0D0!").sensor("0+1.5+2.5+3.5\r\n").view()
    assert by_id(judge_retries(waited, 0.0))["R-7.2-06"].verdict is Verdict.PASS


def test_gave_up_too_soon():
    w = Wire().brk().rec("0!").idle(45).rec("0!").idle(45).rec("0!").idle(300)
    found = by_id(judge_retries(w.view(), 0.0))
    assert found["R-7.2-04"].verdict is Verdict.WARN  # one sequence of three, not three
    assert found["R-7.2-03"].verdict is Verdict.PASS  # two retries, the last after 100 ms
    once = by_id(judge_retries(Wire().brk().rec("0!").idle(300).view(), 0.0))
    assert once["R-7.2-01"].verdict is once["R-7.2-03"].verdict is Verdict.FAIL


def test_repeats_with_a_new_break_are_no_retries():
    """Issue 20: a logger that only repeats break + command passed "implements retries" and
    "whole sequence repeated" on those repeats."""
    w = Wire().brk().rec("0!").idle(300).brk().rec("0!").idle(300).brk().rec("0!")
    found = by_id(judge_retries(w.sensor("0\r\n").view(), 0.0))
    assert found["R-7.2-01"].verdict is Verdict.FAIL
    assert "only after a new break" in found["R-7.2-01"].detail
    assert found["R-7.2-02"].verdict is found["R-7.2-05"].verdict is Verdict.FAIL
    assert found["R-7.2-04"].verdict is Verdict.INCONCLUSIVE  # a SHOULD never fails
    assert {found[r].decision for r in ("R-7.2-01", "R-7.2-04", "R-7.2-06")} == {"T2"}
    assert "no retry in it" in found["R-7.2-04"].detail
    # a parity error, then a break and the command again 1288 ms later: no retry to time
    w = Wire().brk().rec("0D0!").sensor("0+1.5+2.5\r\n", parity=False).idle(1288)
    found = by_id(judge_retries(w.brk().rec("0D0!").sensor("0+1.5+2.5\r\n").view(), 0.0))
    assert found["R-7.2-06"].verdict is Verdict.INCONCLUSIVE
    assert "new sequence" in found["R-7.2-06"].detail
    assert found["R-7.2-01"].verdict is found["R-7.2-05"].verdict is Verdict.FAIL


def test_a_reply_the_recorders_own_break_cut_into_is_not_the_sensors_invalid_reply():
    """Fourteenth round (docs/kit.md): a MicroPython logger polls a reply for 500 ms, then
    breaks and sends the command again, over a long reply still coming. R-7.2-01, -03 and -05
    FAILed "reply '0+1.5+2.' does not end with CR LF ..., then a new sequence": the sensor's
    reply was valid, the recorder cut it. No invalid reply is seen there now, and R-7.2-06
    names the cut. Eighth truth round: the same command sent again after that break is the
    sequence repeated before the response completed (section 7.2: "The data recorder must
    wait for the response to complete before sending a retry"): R-7.2-06 FAILs there."""
    w = Wire().brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n")
    w.t -= 60e-3  # the break starts while the reply's last characters are still coming
    line = w.brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n").view()
    found = by_id(judge_retries(line, 0.0))
    for rid in ("R-7.2-01", "R-7.2-03", "R-7.2-05"):
        assert found[rid].verdict is Verdict.INCONCLUSIVE, found[rid].detail
    assert line.transmissions[0].cut_by is line.breaks[1]
    assert found["R-7.2-06"].verdict is Verdict.FAIL
    assert "break at t=0.129 s cut into the reply '0+1.5+2.'" in found["R-7.2-06"].detail
    assert "sent 0D0! again after it" in found["R-7.2-06"].detail
    # a reply the sensor itself left unfinished (no LF, then 300 ms of marking before the
    # break) is still its invalid reply, and a new break instead of a retry still FAILs
    w = Wire().brk().rec("0D0!").sensor("0+1.5+2.").idle(300)
    line = w.brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n").view()
    assert line.transmissions[0].cut_by is None
    found = by_id(judge_retries(line, 0.0))
    assert found["R-7.2-05"].verdict is found["R-7.2-01"].verdict is Verdict.FAIL
    assert "does not end with CR LF" in found["R-7.2-05"].detail
    # a complete reply, then the break 1 ms after its LF: nothing was cut
    w = Wire().brk().rec("0D0!").sensor("0+1.5\r\n").idle(1)
    assert w.brk().rec("0D1!").view().transmissions[0].cut_by is None


def test_a_break_over_a_reply_then_another_command_is_named_not_failed_r_7_2_06():
    """A break over a reply that the recorder follows with another command is no re-send
    (a recorder may abort): R-7.2-06 names the cut and stays INCONCLUSIVE. So does one over
    a reply already longer than any single line may be (a babbling sensor)."""
    w = Wire().brk().rec("0D0!").sensor("0+1.5+2.5+3.5\r\n")
    w.t -= 60e-3
    found = by_id(judge_retries(w.brk().rec("1M!").sensor("10011\r\n").view(), 0.0))
    assert found["R-7.2-06"].verdict is Verdict.INCONCLUSIVE, found["R-7.2-06"].detail
    assert "cut into the reply" in found["R-7.2-06"].detail
    babble = "0" + "+1.5" * 30 + "\r\n"  # 123 characters: no reply is this long
    w = Wire().brk().rec("0D0!").sensor(babble)
    w.t -= 60e-3
    found = by_id(judge_retries(w.brk().rec("0D0!").sensor("0+1.5\r\n").view(), 0.0))
    assert found["R-7.2-06"].verdict is Verdict.INCONCLUSIVE, found["R-7.2-06"].detail


def test_multi_line_text_the_recorder_broke_into_is_not_waited_for_r_4_4_13_1_04():
    """Fourteenth round: the MicroPython logger's 500 ms poll ended inside the second line of
    0XHELP!'s text and it broke over it: "no multi-line text without ETX was observed". A
    line the recorder's own break cut into is a WARN (the SHOULD: wait 150 ms after the last
    line); one it let end and then waited 150 ms for still PASSes."""
    text = "0\x02first line\r\nsecond line\r\n"
    w = Wire().brk().rec("0XHELP!").sensor(text)
    w.t -= 50e-3  # the break starts inside the second line
    (found,) = judge_multiline_end(w.brk().rec("0I!").view(), None, 0.0)
    assert found.verdict is Verdict.WARN, found.detail
    assert "did not wait for the text to end" in found.detail
    w = Wire().brk().rec("0XHELP!").sensor(text).idle(160)
    (found,) = judge_multiline_end(w.brk().rec("0I!").view(), None, 0.0)
    assert found.verdict is Verdict.PASS, found.detail


def test_a_resend_after_the_retry_window_is_no_retry():
    # aD0! again without a break after a 1.5 s poll timeout: the sensor is in standby
    w = Wire().brk().rec("0D0!").idle(1500).rec("0D0!").sensor("0+1+2\r\n")
    found = by_id(judge_retries(w.view(), 0.0))
    assert found["R-7.2-01"].verdict is Verdict.FAIL and "standby" in found["R-7.2-01"].detail
    assert found["R-7.2-02"].verdict is Verdict.FAIL
    # 95 ms: still heard as a retry, but late; a PASS of R-7.2-01 needs one inside 87 ms
    w = Wire().brk().rec("0!").idle(95).rec("0!").sensor("0\r\n")
    found = by_id(judge_retries(w.view(), 0.0))
    assert found["R-7.2-02"].verdict is Verdict.FAIL
    assert found["R-7.2-01"].verdict is Verdict.INCONCLUSIVE
    # 86.5 ms stamped ±1 ms may be past the window: no PASS on it either
    w = Wire().brk().rec("0!").idle(86.5).rec("0!").sensor("0\r\n")
    assert by_id(judge_retries(w.view(), 1e-3))["R-7.2-01"].verdict is not Verdict.PASS


def test_a_repeated_sequence_with_retries_passes_the_should():
    w = Wire()
    for _ in range(2):
        w.brk().rec("0!").idle(45).rec("0!").idle(45).rec("0!").idle(300)
    found = by_id(judge_retries(w.brk().rec("0!").sensor("0\r\n").view(), 0.0))
    assert found["R-7.2-04"].verdict is found["R-7.2-01"].verdict is Verdict.PASS
    assert found["R-7.2-03"].verdict is found["R-7.2-05"].verdict is Verdict.PASS


def test_crc_mismatch_must_be_retried():
    body = "0+1+2"
    wrong = body + ascii_crc("0+1+3")
    w = _measurement(Wire(), code="MC").sensor("0\r\n", delay_ms=200).idle(9).rec("0D0!")
    w.sensor(wrong + "\r\n")
    line = w.view()
    found = judge_crc_checked(line, 0.0, None, [])
    assert found[0].verdict is Verdict.FAIL
    # the fourteenth round's logger raised on that reply and logged nothing for it: the
    # finding said "accepted a reply whose CRC ..."; what the wire shows is no retry
    found = judge_crc_checked(line, 0.0, {"0MC!": []}, ["+1", "+2"])
    assert found[0].verdict is Verdict.FAIL
    assert found[0].detail.startswith("0D0!: not retried after a reply whose CRC"), found[0].detail
    found = judge_crc_checked(line, 0.0, {"0MC!": ["+1", "+3"]}, ["+1", "+2"])
    assert found[0].verdict is Verdict.FAIL


def test_true_values_logged_after_a_crc_retry_compare_as_numbers():
    """'+1' logged as 1 is the value the sensor sent: no FAIL for a '+' left out (issue 20)."""
    body = "0+1+2"
    w = _measurement(Wire(), code="MC").sensor("0\r\n", delay_ms=200).idle(9).rec("0D0!")
    w.sensor(body + ascii_crc("0+1+3") + "\r\n").idle(30).rec("0D0!")
    line = w.sensor(body + ascii_crc(body) + "\r\n").view()
    found = judge_crc_checked(line, 0.0, {"0MC!": ["1", "2.0"]}, ["+1", "+2"])
    assert found[0].verdict is Verdict.PASS, found[0].detail
    found = judge_crc_checked(line, 0.0, {"0MC!": ["1", "3"]}, ["+1", "+2"])
    assert found[0].verdict is Verdict.FAIL


def test_transparent_commands_pass_unchanged():
    w = Wire().brk().rec("0XSN!").sensor("0EMU\r\n")
    found = by_id(judge_transparent(w.view(), ["0XSN!"], 0.0, {"0XSN!": "0EMU\r\n"}))
    assert found["R-4.4.14-01"].verdict is found["R-4.4.14-02"].verdict is Verdict.PASS
    assert found["R-4.4.13-03"].verdict is Verdict.PASS
    assert found["R-6.3-01"].verdict is Verdict.INCONCLUSIVE  # no metadata command was asked
    changed = Wire().brk().rec("0XSN1!").sensor("0EMU\r\n").view()
    found = by_id(judge_transparent(changed, ["0XSN!"], 0.0, None))
    assert found["R-4.4.14-02"].verdict is found["R-4.4.13-03"].verdict is Verdict.FAIL
    unbroken = Wire().rec("0XSN!").sensor("0EMU\r\n").view()
    found = by_id(judge_transparent(unbroken, ["0XSN!"], 0.0, {"0XSN!": "0EM\r\n"}))
    assert found["R-4.4.14-01"].verdict is Verdict.FAIL


def test_an_extended_command_never_sent_is_no_form_fail_r_4_4_13_03():
    """The twenty-third round's STM32 logger library (ilhamahendra14/STM32L4xx_SDI-12, docs/
    kit.md) sends a! and aI! of a transparent job and cannot send 0XSN! at all: R-4.4.13-03
    (an extended command starts with its address and ends with '!') FAILed "not on the wire as
    typed (sent instead: '0!', '0I!')", commands it was asked for and sent as typed. No
    extended command was on the wire: its form is undecided; R-4.4.14-02 FAILs the absence."""
    w = Wire().brk().rec("0!").sensor("0\r\n").idle(20).brk().rec("0I!").sensor("013EMU\r\n")
    found = by_id(judge_transparent(w.view(), ["0!", "0I!", "0XSN!"], 0.0, None))
    assert found["R-4.4.14-02"].verdict is Verdict.FAIL, found["R-4.4.14-02"].detail
    assert found["R-4.4.13-03"].verdict is Verdict.INCONCLUSIVE, found["R-4.4.13-03"].detail
    for rid in ("R-4.4.14-02", "R-4.4.13-03"):
        assert "sent instead" not in found[rid].detail, found[rid].detail
        assert "0XSN!: never sent" in found[rid].detail, found[rid].detail
    # a recorder's own a! to another address is no extended command changed on its way
    woke = w.idle(20).brk().rec("1!")
    found = by_id(judge_transparent(woke.view(), ["0!", "0I!", "0XSN!"], 0.0, None))
    assert found["R-4.4.13-03"].verdict is Verdict.INCONCLUSIVE, found["R-4.4.13-03"].detail
    # one sent without its address (transparent-drops-address) still FAILs the form
    dropped = woke.idle(20).brk().rec("XSN!").view()
    found = by_id(judge_transparent(dropped, ["0!", "0I!", "0XSN!"], 0.0, None))
    assert found["R-4.4.13-03"].verdict is Verdict.FAIL, found["R-4.4.13-03"].detail
    assert "'XSN!'" in found["R-4.4.13-03"].detail


def test_addresses():
    w = Wire()
    for a in "012345678":
        w.brk().rec(f"{a}!").sensor(f"{a}\r\n", origin=f"sensor{a}").idle(20)
    found = by_id(judge_addresses(w.view(), 0.0))
    assert found["R-4.3-03"].verdict is Verdict.FAIL and "9" in found["R-4.3-03"].detail
    assert found["R-4.3-04"].verdict is Verdict.NA


def test_r_4_3_03_lists_the_unpolled_addresses_as_text():
    """First-hour look (2026-12-05): the FAIL read "addresses never polled successfully:
    ['5', '6', '7', '8', '9']", a Python list in a report meant for a firmware engineer."""
    w = Wire()
    for a in "01234":
        w.brk().rec(f"{a}!").sensor(f"{a}\r\n", origin=f"sensor{a}").idle(20)
    detail = by_id(judge_addresses(w.view(), 0.0))["R-4.3-03"].detail
    assert detail == "addresses never polled successfully: 5, 6, 7, 8, 9"


def test_r_4_4_02_tells_a_command_never_sent_from_one_never_answered():
    """First-hour look (2026-12-05): a recorder that cannot address 5 never sends 0A5!, and
    R-4.4-02 said "never answered validly: 0A5!", which reads as the tool's simulated sensor
    failing to answer. A command not on the wire is "never sent"; one sent whose replies
    were all invalid is still "sent but never answered validly"."""
    w = Wire().brk().rec("0!").sensor("0\r\n").idle(20)
    w = w.brk().rec("0I!").sensor("0I\r\n").idle(20)  # not a valid aI! reply
    found = judge_commands_issued(w.view(), ["0!", "0I!", "0A5!"], 0.0)
    assert found.verdict is Verdict.FAIL
    assert found.detail == "never sent: 0A5!; sent but never answered validly: 0I!"
    # fourteenth round: the MicroPython logger broke over 0I!'s reply 50 ms into it; the
    # sensor answered, the recorder cut it ("sent but never answered validly" blamed the reply)
    w = Wire().brk().rec("0!").sensor("0\r\n").idle(20).brk().rec("0I!")
    w.sensor("013CONFORM EMU001100SN0001\r\n").t -= 180e-3
    found = judge_commands_issued(w.brk().rec("0!").view(), ["0!", "0I!", "0A5!"], 0.0)
    assert found.verdict is Verdict.FAIL
    assert found.detail == "never sent: 0A5!; sent, its reply cut by the recorder's own break: 0I!"


def test_a_concurrent_measurement_repeated_before_its_data_owes_no_values():
    """Seen over RFC 2217 on a busy host: the golden recorder heard 000205 late, sent 0C!
    again (a retry), then read all five values of the second measurement. The first one
    must not FAIL R-4.4.7-08 "read none of the 5 values"; a recorder that never reads the
    data still does."""
    values = "0-5.00-3.75-2.50-1.25+0.00\r\n"
    retried = Wire().brk().rec("0C!").sensor("000205\r\n").idle(100).rec("0C!")
    retried = retried.sensor("000205\r\n").idle(5200).brk().rec("0D0!").sensor(values)
    found = judge_concurrent_storage(observed_measurements(retried.view(), 0.0), ("0C!",))
    assert [f.verdict for f in found if f.requirement == "R-4.4.7-08"] == [Verdict.PASS]
    never = Wire().brk().rec("0C!").sensor("000205\r\n").idle(100).rec("0C!")
    never = never.sensor("000205\r\n").idle(5200).brk().rec("0I!")
    found = judge_concurrent_storage(observed_measurements(never.view(), 0.0), ("0C!",))
    assert Verdict.FAIL in [f.verdict for f in found if f.requirement == "R-4.4.7-08"]


def _unheard(*texts: str) -> Wire:
    """Each command sent three times after a break, never answered (what the played sensors
    do to a wake-up with 5 ms of marking: short-marking, with no retry soon after)."""
    w = Wire()
    for text in texts:
        for _ in range(3):
            w.brk(marking_ms=5.0).rec(text).idle(1500)
    return w


def test_commands_sent_but_never_answered_leave_the_capability_rules_undecided():
    """Recorder combination matrix (short-marking + resends-after-timeout, seed 20): every
    command went out, none was heard, and R-4.4-02, R-4.3-03, R-4.4.7-08 and R-5.4-01 FAILed
    "never sent it" / "not issued" for what R-7.0-06 alone had lost. Sent but unanswered is
    undecided; never sent still FAILs."""
    view = _unheard("0M!", "0C!", "0HA!", "0HB!", *(f"{a}!" for a in "0123456789")).view()
    assert judge_commands_issued(view, ["0M!", "0C!"], 0.0).verdict is Verdict.INCONCLUSIVE
    assert by_id(judge_addresses(view, 0.0))["R-4.3-03"].verdict is Verdict.INCONCLUSIVE
    taken = observed_measurements(view, 0.0)
    sent = {s.text for s in view.transmissions}
    r708 = by_id(judge_concurrent_storage(taken, ("0C!",), sent))["R-4.4.7-08"]
    assert r708.verdict is Verdict.INCONCLUSIVE
    assert by_id(judge_high_volume(taken, True, sent))["R-5.4-01"].verdict is Verdict.INCONCLUSIVE
    # the same rules still FAIL a command, address or kind the recorder never sent
    assert judge_commands_issued(view, ["0M!", "0V!"], 0.0).verdict is Verdict.FAIL
    few = _unheard("0!", "1!").view()
    assert by_id(judge_addresses(few, 0.0))["R-4.3-03"].verdict is Verdict.FAIL
    r708 = by_id(judge_concurrent_storage(taken, ("0C1!",), sent))["R-4.4.7-08"]
    assert r708.verdict is Verdict.FAIL
    nothing = _unheard("0M!").view()
    none_sent = {s.text for s in nothing.transmissions}
    found = by_id(judge_high_volume(observed_measurements(nothing, 0.0), True, none_sent))
    assert found["R-5.4-01"].verdict is Verdict.FAIL


def test_data_commands_never_answered_leave_storage_and_high_volume_undecided():
    """Recorder combination matrix (no-break-after-87ms + no-retries, seed 26): aD0! and
    aDB0! went out after ttt without a break, unheard by the sleeping sensor, and no retry
    followed: R-4.4.7-07 WARNed "read 0 of 99 values" and R-5.4-01 FAILed "not issued or its
    data not read" for R-7.0-17's deviation. A collection that ended on an unanswered data
    command is undecided; one the recorder stopped itself still FAILs."""
    unheard = Wire().brk().rec("0C9!").sensor("000299\r\n").idle(2100).rec("0D0!").idle(200)
    unheard = unheard.brk().rec("0HB!").sensor("0002033\r\n").idle(2100).rec("0DB0!").idle(200)
    unheard = unheard.brk().rec("0HA!").sensor("0002033\r\n").idle(2100).rec("0D0!").idle(200)
    taken = observed_measurements(unheard.view(), 0.0)
    r707 = by_id(judge_concurrent_storage(taken))["R-4.4.7-07"]
    assert r707.verdict is Verdict.INCONCLUSIVE
    assert by_id(judge_high_volume(taken, True))["R-5.4-01"].verdict is Verdict.INCONCLUSIVE
    stopped = Wire().brk().rec("0C9!").sensor("000299\r\n").idle(2100)
    stopped = stopped.brk().rec("0HB!").sensor("0002033\r\n").idle(2100)
    stopped = stopped.brk().rec("0HA!").sensor("0002033\r\n").idle(2100)
    taken = observed_measurements(stopped.view(), 0.0)
    assert by_id(judge_concurrent_storage(taken))["R-4.4.7-07"].verdict is Verdict.WARN
    assert by_id(judge_high_volume(taken, True))["R-5.4-01"].verdict is Verdict.FAIL


def test_a_reply_after_the_recorder_ended_its_job_owes_no_values_r_4_4_8_05():
    """Seventeenth round, HydroSense/SDI12 (docs/kit.md): ``refresh()`` gives up 15 ms after
    queueing ``0C1!`` (before its ``!`` was out) and the logger said done at the stop bit; the
    played sensor's ``000204`` came 9 ms later, and R-4.4.8-05 FAILed "0C1!: stopped after the
    reply with 0 of 4 values" (R-4.4.7-08 "read none"), a reply the recorder never heard. A
    reply begun after the job's end (``ended_parts``) starts no measurement; one begun before
    it, the recorder ending all the same, still FAILs."""
    w = Wire().brk().rec("0C1!")
    end = w.t
    w.sensor("000204\r\n")
    view = w.view()
    sent = {s.text for s in view.transmissions}
    assert judge_data_collection(observed_measurements(view, 0.0))[0].verdict is Verdict.FAIL
    view.ended_parts = {0: end}
    taken = observed_measurements(view, 0.0)
    assert taken == []
    assert judge_data_collection(taken)[0].verdict is Verdict.INCONCLUSIVE
    r708 = by_id(judge_concurrent_storage(taken, ("0C1!",), sent))["R-4.4.7-08"]
    assert r708.verdict is Verdict.INCONCLUSIVE and "never validly answered" in r708.detail
    # the job ended after the reply began: heard, and no D0 followed
    view.ended_parts = {0: end + 0.010}
    found = judge_data_collection(observed_measurements(view, 0.0))
    assert found[0].verdict is Verdict.FAIL and "0 of 4 values" in found[0].detail


def test_an_acknowledge_after_the_measurement_ended_leaves_its_data_owed_r_4_4_7_08():
    """jmpmscorp/esp-sdi-12 (twentieth round, docs/kit.md): its device API sends ``a!`` the
    first time it meets an address, here after ttt and before ``aD0!``. The sensor keeps its
    data until another measurement or a command returning data via D0 (4.4.5, 4.4.7), and the
    wire showed all five values read; R-4.4.7-08 FAILed "read none of the 5 values" and
    R-4.4.8-05 "stopped after the reply with 0 of 5 values". An ``a!`` before ttt (which
    aborts a concurrent measurement, 4.4.7.1) still ends the collection."""
    values = "0-5.00-3.75-2.50-1.25+0.00\r\n"
    after = Wire().brk().rec("0C!").sensor("000205\r\n").idle(2100)
    after = after.brk().rec("0!").sensor("0\r\n").brk().rec("0D0!").sensor(values)
    taken = observed_measurements(after.view(), 0.0)
    found = by_id(judge_concurrent_storage(taken, ("0C!",)) + judge_data_collection(taken))
    assert found["R-4.4.7-08"].verdict is Verdict.PASS, found["R-4.4.7-08"].detail
    assert found["R-4.4.8-05"].verdict is Verdict.PASS, found["R-4.4.8-05"].detail
    measured = Wire().brk().rec("0M!").sensor("00023\r\n").idle(300).sensor("0\r\n")
    measured = measured.brk().rec("0I!").sensor("014CONFORM EMU001100SN0001\r\n")
    measured = measured.brk().rec("0D0!").sensor("0+22.15+1013.2+45.7\r\n")
    found = by_id(judge_data_collection(observed_measurements(measured.view(), 0.0)))
    assert found["R-4.4.8-05"].verdict is Verdict.PASS, found["R-4.4.8-05"].detail
    early = Wire().brk().rec("0C!").sensor("000205\r\n").idle(500)
    early = early.brk().rec("0!").sensor("0\r\n").brk().rec("0D0!").sensor("0\r\n")
    found = judge_concurrent_storage(observed_measurements(early.view(), 0.0), ("0C!",))
    assert Verdict.FAIL in [f.verdict for f in found if f.requirement == "R-4.4.7-08"]


def test_a_command_sent_with_a_nul_after_its_bang_is_not_never_sent_r_4_4_02():
    """Twenty-third round's STM32 logger (ilhamahendra14/STM32L4xx_SDI-12) sends 0A5! and 5A0!
    with the NUL terminator of their char arrays after the '!' (R-4.2-01/R-4.4-04 FAIL it
    rightly), and the played sensor answered them: R-4.4-02 listed them "never sent". They
    are sent, malformed; the FAIL stands on the commands truly unsent (0V!)."""
    w = Wire().brk().rec("0!").sensor("0\r\n").idle(20)
    w = w.brk().rec("0A5!\x00").sensor("5\r\n").idle(1100)
    w = w.brk().rec("5A0!\x00").sensor("0\r\n").idle(1100)
    found = judge_commands_issued(w.view(), ["0!", "0A5!", "5A0!", "0V!"], 0.0)
    assert found.verdict is Verdict.FAIL, found
    assert found.detail == (
        "never sent: 0V!; sent with more after its '!' (its form is R-4.2-01's and "
        "R-4.4-04's): 0A5!<0x00>, 5A0!<0x00>"
    ), found.detail
    # with every other command sent, the malformed ones alone decide nothing here
    found = judge_commands_issued(w.view(), ["0!", "0A5!", "5A0!"], 0.0)
    assert found.verdict is Verdict.INCONCLUSIVE, found
    assert "never sent" not in found.detail, found.detail
