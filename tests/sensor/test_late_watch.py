"""One-shot probes from a sensor seen to start its replies late (truth12).

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then: an
Arduino Due's ``delay(80)``) answered R-7.0-05/-07/-16's probes, each sent once and listened
to 30 ms, after the tool had stopped listening: "no reply" FAILed all three. The engine's own
exchanges show the lateness first (a retry's reply begun too soon to answer it, or its stray
characters, after an unanswered try): :class:`LateStartWatch` keeps that start and
:meth:`SensorSession.hear_late` listens that long after an unanswered probe, so the late reply
is named (INCONCLUSIVE) and silence stays silence. A sensor never seen late is not waited for.
"""

from __future__ import annotations

from conformance.conduct import run_once
from conformance.emulator import sim_sensor
from conformance.judges import exchanges as xjudge
from conformance.sensor.late_watch import LateStartWatch
from conformance.sensor.session import SensorSession
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from tests.support.hand_events import chars


def _tries(reply: str, after_retry: float, *, brk: bool = False) -> LateStartWatch:
    """0I! unanswered, then again 55 ms later whose reply began ``after_retry`` s after it."""
    watch = LateStartWatch()
    first = chars(TOOL, "0I!", 0.0)
    watch.note(Attempt(None, first, [], NO_REPLY, first[-1].end + 0.03), "0I!")
    retry = chars(TOOL, "0I!", first[-1].end + 0.055)
    brk_event = Event(EventKind.BREAK, TOOL, retry[0].start - 0.02, retry[0].start - 0.01)
    heard = chars(DUT, reply, retry[-1].end + after_retry)
    watch.note(Attempt(brk_event if brk else None, retry, heard, OK, heard[-1].end), "0I!")
    return watch


def test_a_retry_answered_too_soon_to_answer_it_shows_the_start() -> None:
    watch = _tries("013CONFORM\r\n", 0.0)
    assert watch.start is not None and abs(watch.start - 0.080) < 1e-9


def test_a_retry_answered_in_time_shows_nothing() -> None:
    assert _tries("013CONFORM\r\n", 9e-3).start is None


def test_a_reply_naming_another_address_shows_nothing() -> None:
    assert _tries("113CONFORM\r\n", 0.0).start is None


def test_a_new_sequence_after_a_break_shows_nothing() -> None:
    assert _tries("013CONFORM\r\n", 0.0, brk=True).start is None


def test_a_sensor_seen_answering_too_soon_is_not_taken_for_late() -> None:
    """response-too-early answers every command 5 ms after it: a retry's reply 5 ms after
    it is its own, not the late reply to the try before (its standby probes were listened
    to for nothing: the run's transcript changed, its verdicts not)."""
    watch = _tries("013CONFORM\r\n", 0.0)
    first = chars(TOOL, "0!", 1.0)
    watch.note(Attempt(None, first, chars(DUT, "0\r\n", first[-1].end + 5e-3), OK, 1.1), "0!")
    assert watch.start is None
    assert _session("response-too-early").master.watch.late.start is None


def _session(*faults: str) -> SensorSession:
    _, link, _ = sim_sensor(faults=faults)
    sensor = SensorSession(link, address="0")
    sensor.master.transact("0I!")  # the engine's own exchange: the lateness, if any, shows
    return sensor


def test_r_7_0_07_probe_from_the_late_sensor_names_its_late_reply() -> None:
    sensor = _session("replies-after-retry")
    assert sensor.master.watch.late.start is not None
    ex = sensor.hear_late(sensor.probe("0!", break_s=13e-3, marking_s=77e-3, standby=True))
    assert not ex.answered
    found = xjudge.answered("R-7.0-07", [ex], "90 ms", first_attempt=True, late_is_reply=True)
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "0! -> late '0<CR><LF>'" in found.detail


def test_a_clean_sensor_is_not_waited_for() -> None:
    sensor = _session()
    assert sensor.master.watch.late.start is None
    ex = sensor.probe("1!", break_s=13e-3, standby=True)  # no sensor there: silence
    before = sensor.link.now()
    assert sensor.hear_late(ex).heard_late == [] and sensor.link.now() == before


def test_silence_from_the_late_sensor_stays_a_fail() -> None:
    """Listened to past its 80 ms: nothing came for 1!, so 'no reply' is evidence."""
    sensor = _session("replies-after-retry")
    ex = sensor.hear_late(sensor.probe("1!", break_s=13e-3, marking_s=77e-3, standby=True))
    assert ex.heard_late == []
    found = xjudge.answered("R-7.0-07", [ex], "90 ms", first_attempt=True, late_is_reply=True)
    assert found.verdict is Verdict.FAIL


def test_r_7_0_15_late_answer_to_a_standby_probe_is_an_answer() -> None:
    """standby-ignored + replies-after-retry (a pair drawing replies-after-retry, seeds
    4500..4757): the a! 101.90 ms after a reply was answered 80 ms late and R-7.0-15 PASSed
    'stayed silent' (a false PASS); now FAIL naming the late answer."""
    data = run_once(
        "sim://?faults=replies-after-retry,standby-ignored", keyword="test_standby_after_100ms"
    )
    found = next(r for r in data["requirements"] if r["id"] == "R-7.0-15")
    assert found["verdict"] == "FAIL", found["findings"]
    assert "0! -> late '0<CR><LF>'" in found["findings"][0]["detail"]


def test_r_7_0_15_late_sensor_that_sleeps_still_passes() -> None:
    data = run_once("sim://?faults=replies-after-retry", keyword="test_standby_after_100ms")
    found = next(r for r in data["requirements"] if r["id"] == "R-7.0-15")
    assert found["verdict"] == "PASS", found["findings"]


def test_one_reply_landing_just_after_the_next_command_does_not_hide_a_late_sensor() -> None:
    """answers-foreign-address + replies-after-retry: a late reply that lands just after the
    next command reads as a first try answered too soon; two late replies outweigh it."""
    watch = _tries("013CONFORM\r\n", 0.0)
    first = chars(TOOL, "0M!", 1.0)
    watch.note(Attempt(None, first, [], NO_REPLY, 1.1), "0M!")
    retry = chars(TOOL, "0M!", first[-1].end + 0.055)
    watch.note(Attempt(None, retry, chars(DUT, "00011\r\n", retry[-1].end), OK, 1.3), "0M!")
    early = chars(TOOL, "0!", 2.0)
    watch.note(Attempt(None, early, chars(DUT, "0\r\n", early[-1].end + 5e-3), OK, 2.1), "0!")
    assert watch.start is not None and abs(watch.start - 0.080) < 1e-9


def _row(faults: str, keyword: str, rid: str) -> dict:
    data = run_once(f"sim://?faults={faults}", keyword=keyword)
    return next(r for r in data["requirements"] if r["id"] == rid)


def test_r_7_0_03_late_answer_after_the_short_pulse_is_an_answer() -> None:
    """wakes-on-short-spacing + replies-after-retry: the a! after the 5 ms pulse and its
    control (a! after a 13 ms break) were each answered 80 ms late; neither was listened to
    that long, so R-7.0-03 was INCONCLUSIVE 'answered none of its own-address controls' on
    a sensor that wakes on the pulse. Both now listen as R-7.0-15's probes do
    (SensorSession.hear_late): FAIL naming the late answer."""
    found = _row(
        "replies-after-retry,wakes-on-short-spacing",
        "test_short_spacing_is_not_a_break",
        "R-7.0-03",
    )
    assert found["verdict"] == "FAIL", found["findings"]  # INCONCLUSIVE before
    assert "0! -> late '0<CR><LF>'" in found["findings"][0]["detail"]


def test_r_7_0_03_late_sensor_silent_after_the_short_pulse_passes() -> None:
    """replies-after-retry alone: silence through the longer listen, and the control's late
    answer shows the sensor listening: PASS (INCONCLUSIVE before)."""
    found = _row("replies-after-retry", "test_short_spacing_is_not_a_break", "R-7.0-03")
    assert found["verdict"] == "PASS", found["findings"]


def test_r_7_0_14_late_answer_after_a_foreign_command_is_an_answer() -> None:
    """stays-awake-after-foreign + replies-after-retry: the a! after z! and the control a!
    were answered 80 ms late: R-7.0-14 was INCONCLUSIVE 'answered none of 0! either'; now
    FAIL naming the late answer, and PASS on replies-after-retry alone."""
    keyword = "test_standby_after_foreign_command"
    found = _row("replies-after-retry,stays-awake-after-foreign", keyword, "R-7.0-14")
    assert found["verdict"] == "FAIL", found["findings"]  # INCONCLUSIVE before
    assert "0! -> late '0<CR><LF>'" in found["findings"][0]["detail"]
    alone = _row("replies-after-retry", keyword, "R-7.0-14")
    assert alone["verdict"] == "PASS", alone["findings"]  # INCONCLUSIVE before


def test_r_7_0_14_late_reply_to_the_foreign_command_is_no_answer_to_the_probe() -> None:
    """answers-foreign-address + replies-after-retry: the sensor's late 'z<CR><LF>' to z!
    came over the a! sent after it (heard by the longer listen): read as 0!'s late answer,
    R-7.0-14 FAILed "0! -> late 'z<CR><LF>'" (with 82d2f2b); it names another address, and
    the probe, sent while the sensor was busy, may not have been heard: INCONCLUSIVE."""
    found = _row(
        "replies-after-retry,answers-foreign-address",
        "test_standby_after_foreign_command",
        "R-7.0-14",
    )
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # FAIL before
    assert "naming another address" in found["findings"][0]["detail"]


def test_r_4_4_6_03_the_late_reply_to_the_ttt_zero_start_is_no_service_request() -> None:
    """partial-command-accepted + replies-after-retry + service-request-extra-chars: 0M1!'s
    '00002' came 80 ms late, in the 0.5 s listened to for a service request: R-4.4.6-03
    FAILed "sent '00002' after '' announced ttt = 000" (truth15); no start reply was taken,
    so nothing announced ttt = 000 this time: INCONCLUSIVE naming the late reply."""
    faults = "partial-command-accepted,replies-after-retry,service-request-extra-chars"
    data = run_once(f"sim://?faults={faults}")  # the whole run: its timing brings it about
    found = next(r for r in data["requirements"] if r["id"] == "R-4.4.6-03")
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # FAIL before
    assert "0M1! -> late '00002<CR><LF>'" in found["findings"][0]["detail"]
