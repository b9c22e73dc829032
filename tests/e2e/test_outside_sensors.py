"""False FAILs the after-landing check of 2026-12-05 (ninth round) found on an outside sensor.

An Arduino Due student sensor (TonyN678/Sdi12-Sensor, docs/kit.md) answers ``?!``, ``aAb!``,
``aM!``, ``aD0!`` and ``aR0!`` but never ``a!``; it replies 15 ms after a command and, for
50 ms after each reply, leaves new commands unread (they are answered late, from its buffer).
Two things the tool said about it were false:

- every rule probed with ``a!`` (R-7.0-04, -05, -07 on waking; R-4.3-03 and R-4.4.4-03 on
  answering at a new address) FAILed on the silence of a sensor that answers no ``a!`` at all:
  that silence is R-4.4.1-01's FAIL, and says nothing about waking or addresses. Now they are
  INCONCLUSIVE "precondition not met: listening" unless the sensor answered an ``a!`` earlier in
  the run or a control ``a!`` sent after the silent probe (``ToolRecorder.acknowledged``,
  ``SensorSession.acknowledgement``, ``preconditions.acknowledges``); its address,
  moved back after a change, was reported "COULD NOT restore" (checked with ``a!``): now
  "moved back ... by its reply ... (not checked)";
- a late reply that began during the tool's retry break went out at the break's end, and the
  tool's command after the break's marking cut it in two (the line queued the rest behind the
  command): the rest read as a reply begun 0 ms after the command, a R-7.0-09 FAIL. The tool's
  recorder already took that tail for contention live; now the view does too
  (``Transmission.cut``, tests/view/test_segments.py).

The tenth round (docs/kit.md) added two: a sensor firmware that talked but never validly
(RTGS-Lab Firmware_-_Aleppo) was sent to its wiring by the "no device answered" stop, and
R-4.4.14-01's PASS for a logger that reports no relayed replies (USDI12 on the C kit) did not
say the relay went unjudged.

The eleventh: a firmware (joembedded/Open-SDI12-Blue) that began a character while the
tool's own command was on the line (its "a0000" after an abort break) was judged on it as a
reply begun 0 ms after the command, cut to '0' by the firmware's own echo check: R-4.2-03
FAILed "reply '0' does not end with CR LF". The harness bus now marks such a character
COLLISION (two talkers), which the view takes for contention.

The twelfth: a PIC18 firmware (RxTx1200/SDI-12_slave) answered '0' to 'jA9!' and went deaf at
'9' (it takes only lowercase letters as addresses): R-4.4.4-01 was N/A "not software-settable"
and every later case judged the silence of a lost sensor; now the trial's third address FAILs
R-4.4.4-01 and a sensor lost by an address change stops the run. A Python logger (lories'
Sdi12Connector) ends each command with CR LF: the recorder view took '0M!<CR><LF>' for no
command, its values as "logged, the command never sent" and its measurement flow and retries as
unobserved; now the command is read up to its '!' (``Transmission.stem``).

The thirteenth: an AVR firmware (uRADMonitor, radhoo/sdi12) takes the leading spacing of the
unbroken a! that shows it asleep for a break and waits 100 ms for a '!', blind to breaks: its
silence after R-7.0-03's 5 ms pulse PASSed, though it wakes on 2 ms of spacing, because the
control (a real break and a!) was sent without that a! before it. The control now repeats the
probe's whole prelude.

The fourteenth (two loggers): a MicroPython ESP32 driver polls a reply for 500 ms, then breaks
and sends the command again over a reply still coming; the part before its break read as the
sensor's invalid reply (R-7.2-01/-03/-05 FAILed "does not end with CR LF"), and a multi-line
text it broke into as "no multi-line text without ETX was observed". Their tests are the
recorder judges' (tests/judges/recorder/test_recorder_judges.py, ``Transmission.cut_by``).

The fifteenth: a Raspberry Pi Pico PT100 sensor (PIO UART, on the C kit's UART adapter) reads
its RTD for 30 ms before it answers ``aM1!``..``aM7!``: its '00001' came 32 ms after each try,
between the tool's retries. R-4.4.9-01 and R-4.4.12-01 FAILed "no reply although silence does
not comply" and R-4.4.9-02 WARNed "undefined group answered 0M1! -> '(silence)'": a sensor that
answered, late (R-7.0-10's FAIL). A reply heard after a try's window and before the next try
(``exchanges.late_reply``) is no silence for the rules that ask only for a reply.

The sixteenth: a sensor sketch on EnviroDIY's library (spectraphilic/wsn_arduino's lagopus, at
address '5') listens from 0.5 s after power-up but reads its buffer only from 1.5 s, after
its sensors' set-up: the tool's ?!s went unanswered, it assumed '0', and the sketch's late
answers to the buffered ?!s, '5<CR><LF>' twice, came 1.5 ms after the tool's '0!'. The tool
took that for a! answered at '0' and judged the sensor there: a!, aI! and every command
FAILed on the silence of a sensor at '5'. A reply to a! that is a bare other address is no
device at the assumed address now; ?! is asked again and its answer taken
(``SensorSession._answered_here``). Its parser answers aCn! with its a! reply, and R-4.4.7-02
(aC! measures for real) PASSed on those while aC! and aCC! were silent: it is judged on plain
aC!/aCC! only.

The twentieth: an ESP-IDF logger library (jmpmscorp/esp-sdi-12) sends a! the first time it
meets an address, between aC! and aD0!: the recorder judges took that for the end of the
measurement and FAILed R-4.4.7-08, R-4.4.8-05 and R-4.4-02 on values read on the wire. A sensor
sketch (joembedded/SDI_12_slave) answers every aC...! '0UNKN': R-4.4.7-08 and R-4.4.12-01
(support of aC! and aCC!) PASSed on that text.

The twenty-first: an Arduino Due sensor (ShadmanKroos' ENG-20009 sketch) answers 100 ms late,
and any '?' command with its address: the '0' for the ?I! probe came 14 ms after the 0A1!
sent next, which it never heard, and R-4.3-03 FAILed "refused or lost address(es) 1". A change
reply that may be the late reply of the unanswered command before it is asked again
(``address_change.may_be_late_reply_to``). Its silent aD0!s PASSed R-4.4.8-04 and its aI!
text to aIM! PASSed R-6.1-01.

The twenty-second: an STM32 logger (davemortek/stm32-sdi-12) sends aM0!, which no sensor
answers, and reads ttt from the empty reply, ``(response[1] - 48) * 100000 + ...``: a
HAL_Delay of 4289639296 ms. Its harness said so, ``wait 4289644352000``, and the run stopped
"time beyond 10^12 us (units wrong?)" with every later case ERROR. A ``wait`` is a long
sleep (the job's budget ends it); only ``tx``/``brk`` times keep the bound.

The twenty-third: an Arduino Due sensor (Riley-Tuckett/SDI-12SensorProject) answers only
``?!`` and ``aAb!`` (no ``a!``). The address sweep's restore after '1' said "moved back to '0'
by its reply to 1A0! (not checked)", then the sweep's closing restore asked again, with
``a!``, which it never answers, sent ``1A0!`` to a sensor at '0' and reported "COULD NOT
restore the address"; its silence to ``0A$!`` (it refuses '$') was reported the same way, though
``?!`` still answered '0'. A restore no change has followed since is not done again, and a
sensor that answers no ``a!`` is found at its address by ``?!``.

The twenty-sixth: an STM32 HAL logger (HarveyBates/stm32-projects) sends each command with its
C string's NUL (``0M!<NUL>``): the view took it for no command though the played sensor answered
at the ``!``, so its measurements and retries went unjudged; now NULs after the ``!`` keep it a
command (``Transmission.stem``), and its aD1! in place of a lost aD0! FAILs R-4.4.5-05.

The twenty-ninth: the uOS++ RTOS sensor hangs for 5 s after R-7.0-05's command 2 ms after a
break, and R-7.0-07 FAILed on the hang (the case now sends a control a! after a silent
probe); its early reply to aD0! after a break, 93 ms after the try before, was taken for that
try's late reply (R-7.1-02 undecided where it FAILs); a mock sensor sketch silent to aMn!
had its groups called "defined" (R-4.4.8-03's N/A).

The thirty-first: a test slave on EnviroDIY's slave API whose parser reads only the 'I'
answered every ``aIM_nnn!`` with its ``aI!`` identification, and R-6.2-01 PASSed "conforms (30
checked)" (now FAIL, as R-6.1-01 already did for ``aIM!``).
"""

from __future__ import annotations

import json
import re
from dataclasses import replace

import pytest

from conformance.conduct import run_into, run_once
from conformance.emulator.faults import FaultSet
from conformance.emulator.replies import ReplyKind
from conformance.harness.device import HarnessBus
from conformance.protocol.commands import Kind
from conformance.protocol.timing import CHAR_TIME
from conformance.recorder.golden import GoldenRecorder
from conformance.sim.bus import Frame
from conformance.transcript import COLLISION, DUT
from conformance.view.runs import segments
from tests.support.harness_script import ASK, PRELUDE

#: The cases that probe with a! (and R-4.4.1-01's own).
A_PROBES = (
    "test_acknowledge_active or test_address_range or test_change_address or "
    "test_ready_within_100ms_of_break or test_break_just_over_12ms_wakes or "
    "test_marking_after_break"
)
#: The rules those cases judged on the silence of a sensor that answers no a!.
#: (R-4.3-03 is not among them: a sensor that answers ?! and aAb! is judged on those replies.)
ON_A_SILENCE = ("R-4.4.4-03", "R-7.0-04", "R-7.0-05", "R-7.0-07")


def _verdicts(data: dict) -> dict[str, dict]:
    return {r["id"]: r for r in data["requirements"]}


@pytest.fixture
def a_never_answered(monkeypatch):
    """The simulated sensor, every reply as usual but ``a!``'s (the Due sensor's way)."""
    usual = FaultSet.rewrite

    def rewrite(self, reply):
        return None if reply.kind is ReplyKind.ACKNOWLEDGE else usual(self, reply)

    monkeypatch.setattr(FaultSet, "rewrite", rewrite)


def test_a_sensor_that_never_answers_a_is_judged_on_a_only_by_r_4_4_1_01(a_never_answered):
    found = _verdicts(run_once("sim://", keyword=A_PROBES))
    assert found["R-4.4.1-01"]["verdict"] == "FAIL"
    for rid in ON_A_SILENCE:
        assert found[rid]["verdict"] == "INCONCLUSIVE", (rid, found[rid]["findings"])
        details = " ".join(f["detail"] for f in found[rid]["findings"])
        assert "answered no 0!" in details, (rid, details)
    assert found["R-4.4.4-01"]["verdict"] == "PASS"  # it took the new address: its reply says so
    # and went back by its reply: never "COULD NOT restore" (its a! being the only check)
    note = found["R-4.4.4-01"]["findings"][0]["detail"]
    assert "moved back to '0' by its reply" in note and "COULD NOT" not in note, note


def test_the_same_cases_still_fail_a_sensor_that_answers_a_but_wakes_too_slowly():
    """The precondition holds wherever an a! was answered: slow-wake (110 ms after a break,
    its retries answered) still FAILs R-7.0-07 on the silence of its first try."""
    found = _verdicts(run_once("sim://?faults=slow-wake", keyword=A_PROBES))
    assert found["R-7.0-07"]["verdict"] == "FAIL"
    assert found["R-4.4.1-01"]["verdict"] == "PASS"


def test_a_sensor_that_talked_is_not_sent_to_the_wiring():
    """An outside sensor firmware (RTGS-Lab Firmware_-_Aleppo, docs/kit.md) has no a! reply,
    prints its replies without CR LF and answers whatever stale command its UART buffer
    holds: it answered the first ?! with '0', then nothing the tool took for a reply to a!,
    aI! or the last ?!. The tool stopped with "no device answered ... Check wiring and
    power". The stop (exit 5, still no verdict) now says the device talked, what it sent
    first, and to check its reply format. Here: a sensor that answers ?! once, then only
    silence."""
    from conformance.emulator import sim_sensor
    from conformance.sensor.session import NoDeviceAnswered, SensorSession

    class OnceOnQuery(FaultSet):
        queries = 0

        def rewrite(self, reply):
            if reply.kind is ReplyKind.ADDRESS:
                OnceOnQuery.queries += 1
                return super().rewrite(reply) if OnceOnQuery.queries == 1 else None
            return None

    _, link, emulator = sim_sensor()
    emulator.faults = OnceOnQuery(emulator.faults.faults, emulator.behaviour)
    with pytest.raises(NoDeviceAnswered) as stop:
        SensorSession(link).discover()
    said = str(stop.value)
    assert "The device did talk" in said and "'0<CR><LF>'" in said, said
    assert "Check wiring" not in said, said


def test_total_silence_still_sends_the_user_to_the_wiring():
    from dataclasses import replace

    from conformance.emulator import sim_sensor
    from conformance.sensor.session import NoDeviceAnswered, SensorSession

    _, link, emulator = sim_sensor()
    emulator.behaviour = replace(emulator.behaviour, break_threshold=1.0)
    with pytest.raises(NoDeviceAnswered, match="Check wiring") as stop:
        SensorSession(link, address="0").discover()
    assert "did talk" not in str(stop.value)


class _RelaysUnreported(GoldenRecorder):
    """The golden recorder, its transparent-mode replies not reported (as an outside logger
    on the C kit's recorder adapter, which has no call for them)."""

    def __call__(self, request, link):
        out = super().__call__(request, link)
        out.relayed.clear()
        return out


def relays_unreported() -> GoldenRecorder:
    return _RelaysUnreported()


def test_a_transparent_pass_says_when_the_relay_was_not_judged():
    """USDI12 (jwidess/uart-sdi12, docs/kit.md) in transparent mode: R-4.4.14-01 PASSed
    "passed through" on the break and the command seen on the wire, though the relay of the
    reply to the host, which the rule also asks, was never reported. The PASS stands (what
    the wire shows conforms) and now says the relay was not judged; with relays reported
    (the golden recorder) it reads as before."""
    keyword = "test_transparent_mode"
    port = "sim:?recorder=tests.e2e.test_outside_sensors:relays_unreported"
    unreported = _verdicts(run_once(port, role="recorder", keyword=keyword))["R-4.4.14-01"]
    reported = _verdicts(run_once("sim", role="recorder", keyword=keyword))["R-4.4.14-01"]
    assert unreported["verdict"] == reported["verdict"] == "PASS"
    assert "were not reported: not judged" in unreported["findings"][0]["detail"]
    assert "not judged" not in reported["findings"][0]["detail"]


class _KitLikeTalker:
    """A harness device that wants to send ``wire`` from ``at`` on and, told of a character
    of the tool's that its frame would overlap, plans it again where that character ends, as
    the firmware kit does for a sketch that began a frame inside the line's last character
    ("it goes out from ..." on stderr): the plan then meets the tool's next character of a
    command at the instant it starts, and the tool's goes first."""

    name = "kit-like"

    def __init__(self, wire: int, at: float) -> None:
        self.frames = [Frame(at, wire)]

    def on_break(self, start: float, end: float) -> None:
        self.on_char(0, start, end)

    def on_char(self, wire: int, start: float, end: float) -> None:
        if self.frames and self.frames[0].start < end:
            self.frames[0] = Frame(end, self.frames[0].wire)

    def next_frame(self) -> Frame | None:
        return self.frames[0] if self.frames else None

    def pop_frame(self) -> Frame:
        return self.frames.pop(0)


def _sent(bus: HarnessBus, text: str, start: float) -> None:
    for k, c in enumerate(text.encode()):
        bus.tool_char(c, start + k * CHAR_TIME)
    bus.advance(start + len(text) * CHAR_TIME + 0.1)


@pytest.mark.parametrize("begun", [0.004, 0.012])  # inside the command's '0', inside its 'M'
def test_a_character_begun_over_the_tools_command_is_contention_not_a_reply_r_4_2_03(begun):
    bus = HarnessBus()
    bus.attach(_KitLikeTalker(ord("0"), begun))
    _sent(bus, "0M!", 0.0)
    dut = [e for e in bus.transcript.events if e.origin == DUT]
    assert len(dut) == 1 and dut[0].start == pytest.approx(3 * CHAR_TIME)  # after the command
    assert dut[0].text == COLLISION  # it wanted the line while the tool had it
    (seg,) = segments(bus.transcript.events)
    assert seg.reply == [] and seg.contention == dut  # no reply '0' without CR LF


def test_a_reply_planned_at_the_commands_end_is_still_the_reply():
    """A sensor that answers 0 ms after the command (libsdi12's example, docs/kit.md) planned
    it when it heard the '!': no character of the tool's went ahead of it."""
    bus = HarnessBus()
    talker = _KitLikeTalker(ord("0"), 99.0)
    bus.attach(talker)
    bus.tool_char(ord("0"), 0.0)
    bus.tool_char(ord("M"), CHAR_TIME)
    bus.tool_char(ord("!"), 2 * CHAR_TIME)
    talker.frames = [Frame(3 * CHAR_TIME, ord("0"))]  # planned on hearing the '!'
    bus.advance(1.0)
    dut = [e for e in bus.transcript.events if e.origin == DUT]
    assert [e.text for e in dut] == [""]
    assert [s.reply for s in segments(bus.transcript.events)][-1] == dut


def test_a_sensor_at_another_address_is_named_not_sent_to_its_reply_format():
    """First-hour look (2026-12-05): ``--port sim --address 7`` (the sim is at 0) stopped
    with "?! was answered '0<CR><LF>'. The device did talk ... check its reply format (CR LF)
    and address, not the wiring": the reply was well-formed, the address was the only fault.
    The stop now names the address the device answered at and how to judge it there."""
    from conformance.emulator import sim_sensor
    from conformance.sensor.session import NoDeviceAnswered, SensorSession

    _, link, _ = sim_sensor()
    with pytest.raises(NoDeviceAnswered) as stop:
        SensorSession(link, address="7").discover()
    said = str(stop.value)
    assert "the device is at address '0'" in said and "--address 0" in said, said
    assert "reply format" not in said and "Check wiring" not in said, said


def _address_change_undeclared(monkeypatch) -> None:
    """The DUT's declaration says nothing of ``aAb!`` (an exec: firmware with none), so the
    tool tries the change."""
    from conformance.sensor.session import SensorSession

    declared = SensorSession.feature
    monkeypatch.setattr(
        SensorSession,
        "feature",
        lambda self, name: None if name == "address_change" else declared(self, name),
    )


@pytest.fixture
def lost_after_address_change(monkeypatch):
    """The simulated sensor as the twelfth round's PIC firmware (RxTx1200/SDI-12_slave,
    docs/kit.md) behaves: ``aAb!`` moves it, its reply names a third address (the firmware
    answers with the EEPROM's first slot, '0' to 'jA9!'), and from then on it answers nothing
    anywhere (it takes only lowercase letters as addresses, so at '9' it is deaf). Its address
    change is not declared (an exec: firmware with no declaration), so the tool tries it."""
    _address_change_undeclared(monkeypatch)
    usual = FaultSet.rewrite
    moved = []

    def rewrite(self, reply):
        if moved:
            return None
        if reply.kind is ReplyKind.CHANGE_ADDRESS:
            moved.append(reply.body)
            return replace(reply, body="5")
        return usual(self, reply)

    monkeypatch.setattr(FaultSet, "rewrite", rewrite)


#: a! answered, the address-change case, then a case that judges waking on a! silence.
LOST_CASES = "test_acknowledge_active or test_change_address or test_ready_within_100ms_of_break"


def test_r_4_4_4_01_fails_a_change_answered_with_a_third_address(lost_after_address_change):
    """'0A9!' answered '5': neither the new address nor the unchanged old one (R-4.4.4-01
    allows those two only). The tool took the reply for "not software-settable" and said N/A."""
    found = _verdicts(run_once("sim://", keyword=LOST_CASES))
    rule = found["R-4.4.4-01"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    detail = " ".join(f["detail"] for f in rule["findings"])
    assert "'5'" in detail and "neither" in detail, detail


def test_a_sensor_lost_after_an_address_change_stops_the_run(lost_after_address_change):
    """A sensor that answered a! before the change, and at no address tried after it, is
    lost: every later case would judge its silence (R-7.0-07 FAILed "no reply ... 90 ms after
    the break" on the PIC firmware, which wakes in 8 ms). The run stops there, INCOMPLETE."""
    data = run_once("sim://", keyword=LOST_CASES)
    found = _verdicts(data)
    assert found["R-7.0-07"]["verdict"] != "FAIL", found["R-7.0-07"]["findings"]
    assert not data["run"]["complete"]
    assert "lost" in data["run"]["stop_reason"] and "'0'" in data["run"]["stop_reason"], data[
        "run"
    ]["stop_reason"]


@pytest.fixture
def commands_end_in_cr_lf(monkeypatch):
    """The golden recorder, every command written with CR LF after its '!' (a PC logger's
    way: lories' Sdi12Connector writes f"{address}M!\\r\\n" through pyserial, twelfth round)."""
    from conformance.tool_recorder import engine

    encode = engine.encode_7e1
    monkeypatch.setattr(
        engine, "encode_7e1", lambda text: encode(text + "\r\n" if text.endswith("!") else text)
    )


#: the measurement flow's cases (its wait for data, what it logged)
FLOW_CASES = "test_waiting_for_the_service_request or test_logged_values_are_the_values_sent"


def test_a_command_with_cr_lf_after_its_bang_is_still_that_command(commands_end_in_cr_lf):
    """A sensor answers at the '!', so '0M!<CR><LF>' started a measurement: the values logged
    for it were "logged, the command never sent" (R-4.4-02) and its wait for data went
    unjudged ("no wait for data was observed"). The CR LF itself stays R-4.4-04's FAIL."""
    found = _verdicts(
        run_once("sim", role="recorder", keyword=FLOW_CASES + " or test_command_text")
    )
    assert found["R-4.4-04"]["verdict"] == "FAIL"
    assert found["R-4.4.5-04"]["verdict"] == "PASS", found["R-4.4.5-04"]["findings"]
    logged = " ".join(f["detail"] for f in found["R-4.4-02"]["findings"])
    assert "never sent" not in logged, logged
    assert found["R-4.4-02"]["verdict"] == "PASS", found["R-4.4-02"]["findings"]


def test_retries_of_a_command_with_cr_lf_after_its_bang_are_judged(commands_end_in_cr_lf):
    """The retry rules looked only at transmissions ending in '!': every retry of
    '0M!<CR><LF>' went unseen, R-7.2-01 "nothing was observed" (lories' connector, which
    never retries, was not FAILed for it)."""
    found = _verdicts(run_once("sim", role="recorder", keyword="test_retries"))
    assert found["R-7.2-01"]["verdict"] == "PASS", found["R-7.2-01"]["findings"]


#: A firmware's 100 ms wait for a '!' after what it took for a break (s): uRADMonitor's.
WAIT_FOR_BANG = 0.1


@pytest.fixture
def blind_after_an_unbroken_command(monkeypatch):
    """The simulated sensor, as uRADMonitor's SDI-12 firmware (radhoo/sdi12) behaves: a
    command heard in standby, without a break, leaves it blind to breaks for the next 100 ms
    (the firmware polls for a break by counting, takes the command's leading spacing for one,
    then only waits up to 100 ms for a '!', not looking for breaks); a break in that time
    goes unseen, so the command after it is not answered either."""
    from conformance.emulator.sensor import SensorEmulator

    on_char, on_break = SensorEmulator.on_char, SensorEmulator.on_break

    def hear(self, wire, start, end):
        if not self.awake(start):
            self._blind_until = end + WAIT_FOR_BANG
        on_char(self, wire, start, end)

    def brk(self, start, end):
        if start < getattr(self, "_blind_until", float("-inf")):
            return  # the firmware was waiting for a '!', not polling for a break
        on_break(self, start, end)

    monkeypatch.setattr(SensorEmulator, "on_char", hear)
    monkeypatch.setattr(SensorEmulator, "on_break", brk)


def test_silence_after_a_short_pulse_counts_only_if_the_same_prelude_lets_a_break_through_r_7_0_03(
    blind_after_an_unbroken_command,
):
    """uRADMonitor's firmware takes 2 ms of spacing for a break (its 5000-count poll is 2 ms
    of a 14.7456 MHz AVR, not the 12 ms its comment says), so a 5 ms pulse wakes it: a
    R-7.0-03 fault. The tool PASSed R-7.0-03 "stayed silent (a 5.00 ms spacing is not a
    break)": the a! without a break that showed it asleep had left it blind (its leading
    spacing taken for a break, then 100 ms of waiting for a '!'), and the control, a 13 ms
    break and a!, was sent without that a! before it, so it was answered. Here: the simulated
    sensor waking on 4 ms of spacing (wakes-on-short-spacing) and blind as the firmware is.
    The control now follows the probe's own prelude: it goes unanswered, so R-7.0-03 is not
    decided on that silence."""
    found = _verdicts(
        run_once("sim://?faults=wakes-on-short-spacing", keyword="test_short_spacing")
    )
    rule = found["R-7.0-03"]
    assert rule["verdict"] == "INCONCLUSIVE", rule["findings"]
    assert "listening" in " ".join(f["detail"] for f in rule["findings"])


def test_a_sensor_woken_by_a_short_pulse_still_fails_r_7_0_03():
    """Without the blindness the same fault FAILs R-7.0-03, as before: the control's own a!
    without a break does not stop a sensor that hears breaks from being judged."""
    found = _verdicts(
        run_once("sim://?faults=wakes-on-short-spacing", keyword="test_short_spacing")
    )
    assert found["R-7.0-03"]["verdict"] == "FAIL", found["R-7.0-03"]["findings"]


def test_a_blind_sensor_that_ignores_short_pulses_is_not_failed_for_them(
    blind_after_an_unbroken_command,
):
    """The blindness alone (breaks of 9 ms or more, as the simulated sensor takes them):
    R-7.0-03 is not FAILed on it, and R-7.0-04 FAILs, the 12.6 ms break after the unbroken
    a! going unseen (true of such a firmware: it misses a break it should take; its a!
    answered after a break in test_acknowledge_active shows its silence is not R-4.4.1-01's)."""
    keyword = "test_acknowledge_active or test_short_spacing or test_break_just_over_12ms_wakes"
    found = _verdicts(run_once("sim://", keyword=keyword))
    assert found["R-7.0-03"]["verdict"] != "FAIL", found["R-7.0-03"]["findings"]
    assert found["R-7.0-04"]["verdict"] == "FAIL", found["R-7.0-04"]["findings"]


@pytest.fixture
def numbered_groups_answer_late(monkeypatch):
    """The simulated sensor, every aMn!/aMCn! (n >= 1) start reply 24 ms later than usual,
    about 33 ms after the command (the Pico firmware's RTD read before its reply)."""
    from conformance.emulator.sensor import SensorEmulator
    from conformance.protocol.commands import Kind

    usual = SensorEmulator._send

    def _send(self, reply, at):
        cmd = reply.command
        numbered = cmd is not None and cmd.kind is Kind.MEASURE and cmd.group > 0
        late = reply.kind is ReplyKind.START and numbered
        return usual(self, reply, at + (24e-3 if late else 0.0))

    monkeypatch.setattr(SensorEmulator, "_send", _send)


def test_a_late_reply_to_a_numbered_group_is_not_silence_r_4_4_9_01(numbered_groups_answer_late):
    found = _verdicts(run_once("sim://"))
    assert found["R-7.0-10"]["verdict"] == "FAIL"  # the deviation: the reply comes too late
    for rid in ("R-4.4.9-01", "R-4.4.9-02", "R-4.4.12-01"):
        assert found[rid]["verdict"] == "INCONCLUSIVE", (rid, found[rid]["findings"])
        details = " ".join(f["detail"] for f in found[rid]["findings"])
        assert "answered only after the reply window" in details and "late '0" in details


def test_a_numbered_group_never_answered_still_fails_r_4_4_9_01():
    found = _verdicts(run_once("sim://?faults=undefined-measure-silent"))
    assert found["R-4.4.9-01"]["verdict"] == "FAIL"
    assert found["R-4.4.9-02"]["verdict"] == "WARN"


#: The sixteenth round's sketch hears the line from 0.5 s after power-up (setup()'s
#: delay(500), then forceListen()) and reads what it kept from 1.5 s (a 1 s heater pulse).
LISTENS = 0.5


def boots_late(monkeypatch, reads_from: float) -> None:
    """The simulated sensor (at '1': factory-address-not-zero) deaf until ``reads_from``,
    keeping what it heard from LISTENS on; the first command it hears after that is
    followed, 1.5 ms after its '!', by its answers to the ?!s it kept (the lagopus sketch's
    '5<CR><LF>' twice after the tool's 0!)."""
    from conformance.emulator.replies import Reply
    from conformance.emulator.sensor import SensorEmulator

    on_char = SensorEmulator.on_char

    def hear(self, wire, start, end):
        kept = getattr(self, "_kept_at_boot", None)
        if kept is None:
            kept = self._kept_at_boot = []
        if start < reads_from:
            if start >= LISTENS:
                kept.append(chr(wire & 0x7F))
            return
        on_char(self, wire, start, end)
        queries = "".join(kept).count("?!")
        if queries and chr(wire & 0x7F) == "!":
            kept.clear()
            for n in range(queries):
                self._send(Reply(ReplyKind.ADDRESS, self.address), end + 1.5e-3 + n * 33e-3)

    monkeypatch.setattr(SensorEmulator, "on_char", hear)


@pytest.mark.parametrize(
    "reads_from",
    [1.45, 1.2],
    ids=[
        "answers-after-a",
        "answers-after-aI",
    ],  # the tool's probes then: 0! at 1.49 s, 0I! at 1.21 s
)
def test_a_late_answer_naming_another_address_is_no_sensor_at_the_assumed_one(
    monkeypatch, reads_from
):
    boots_late(monkeypatch, reads_from)
    data = run_once(
        "sim://?faults=factory-address-not-zero",
        keyword="test_acknowledge_active or test_identification",
    )
    found = _verdicts(data)
    for rid in ("R-4.4.1-01", "R-4.4.2-01"):
        assert found[rid]["verdict"] == "PASS", (rid, found[rid]["findings"])
    said = " ".join(data["dut"]["assumptions"])
    assert "?! asked again was answered '1': the device is judged there" in said, said


@pytest.fixture
def plain_concurrent_silent(monkeypatch):
    """The simulated sensor silent to plain aC! and aCC! (the lagopus sketch's parser knows
    no C; what it answered to aCn! was its a! answer, which reaches the same rule)."""
    from conformance.protocol.commands import Kind

    usual = FaultSet.rewrite

    def rewrite(self, reply):
        cmd = reply.command
        plain = cmd is not None and cmd.kind is Kind.CONCURRENT and cmd.group == 0
        return None if plain and reply.kind is ReplyKind.START else usual(self, reply)

    monkeypatch.setattr(FaultSet, "rewrite", rewrite)


def test_r_4_4_7_02_is_not_judged_on_numbered_concurrent_groups(plain_concurrent_silent):
    """R-4.4.7-02 (aC! starts a real measurement: 'a00000' does not conform) PASSed
    "conforms (18 checked: 0C1!, ...)" on a sensor that answered no plain aC!/aCC! at all:
    an aCn! reply cannot break the rule. It is not decided now; R-4.4.7-08 FAILs the
    silence, as before."""
    found = _verdicts(
        run_once("sim://", keyword="test_concurrent_reply or test_concurrent_supported")
    )
    rule = found["R-4.4.7-02"]
    assert rule["verdict"] == "INCONCLUSIVE", rule["findings"]
    assert found["R-4.4.7-08"]["verdict"] == "FAIL"
    assert found["R-4.4.7-01"]["verdict"] == "PASS"  # the numbered groups' form is still judged


def test_a_late_reply_to_a_basic_command_is_not_silence_r_4_4_01(numbered_groups_answer_late):
    """R-4.4-01 asks for a well-formed answer to every basic command, not for its timing:
    '00001' to 0M1!..0M9!, heard 33 ms after each try, is R-7.0-10's deviation (its FAIL);
    R-4.4-01 FAILed "no reply although it is a basic command: 0M1!; ..." (docs/kit.md,
    fifteenth round, left to issue 10's "probably a consequence")."""
    found = _verdicts(run_once("sim://", keyword="test_every_basic_command_is_answered"))
    row = found["R-4.4-01"]
    assert row["verdict"] == "INCONCLUSIVE", row["findings"]
    details = " ".join(f["detail"] for f in row["findings"])
    assert "answered only after the reply window" in details and "0M1! -> late '0" in details


def test_a_basic_command_never_answered_still_fails_r_4_4_01():
    found = _verdicts(
        run_once("sim://?faults=undefined-measure-silent", keyword="test_every_basic_command")
    )
    assert found["R-4.4-01"]["verdict"] == "FAIL", found["R-4.4-01"]["findings"]


@pytest.fixture
def lost_without_acknowledging(monkeypatch):
    """The simulated sensor as the eighteenth round's Arduino Due sensor (Samch458/SDI12-
    sensor-and-data-logger, docs/kit.md) behaves: it answers no ``a!``; ``aAb!`` moves it
    (its reply names the new address), after which it is at an address no command can name
    (the sketch's ``deviceAddress = newAddr - '0'``: -12 for '$') and answers only ``?!``,
    with '-12'. Its address change is not declared, so the tool tries it."""
    _address_change_undeclared(monkeypatch)
    usual = FaultSet.rewrite
    moved = []

    def rewrite(self, reply):
        if reply.kind is ReplyKind.ACKNOWLEDGE:
            return None
        if moved:
            return replace(reply, body="-12") if reply.kind is ReplyKind.ADDRESS else None
        if reply.kind is ReplyKind.CHANGE_ADDRESS:
            moved.append(reply.body)
        return usual(self, reply)

    monkeypatch.setattr(FaultSet, "rewrite", rewrite)


def test_a_sensor_that_answers_no_a_and_is_lost_after_a_change_stops_the_run(
    lost_without_acknowledging,
):
    """Its restore cannot be checked with a!; ?! answered '-12' now (it was '0') shows it
    gone. Before, the run went on and R-6.1-01 FAILed "no reply although v1.4 makes them
    mandatory" on the silence of an address it no longer had."""
    data = run_once("sim://", keyword="test_change_address or test_identify_measurement_answered")
    found = _verdicts(data)
    assert found["R-6.1-01"]["verdict"] != "FAIL", found["R-6.1-01"]["findings"]
    assert not data["run"]["complete"]
    reason = data["run"]["stop_reason"]
    assert "lost" in reason and "?! is answered '-12" in reason, reason


def test_r_4_0_01_fails_a_sensor_that_answers_a_command_ending_in_its_address():
    """The sixteenth round's lagopus sketch at '5' answers ``0M5!`` as ``5!``: its parser
    starts over at its address. The foreign probes (a!, aI!, aM! at spare addresses, and the
    exploration's D0 form at '0') never end in '5'; the probe ``zD5!`` does, and its answer
    FAILs R-4.0-01 (passed before: nothing the suite sent ended in '5!')."""
    found = _verdicts(
        run_once(
            "sim://?faults=answers-trailing-address&address=5",
            keyword="test_foreign_addresses_are_ignored or test_exploration",
        )
    )
    assert found["R-4.0-01"]["verdict"] == "FAIL"
    details = " ".join(f["detail"] for f in found["R-4.0-01"]["findings"])
    assert "zD5!" in details, details


def test_the_probe_ending_in_the_address_is_silent_on_the_clean_sensor_at_a_letter():
    """At a letter address the probe is a change of address (``zAb!``), a valid command for
    'z' that no sensor holds: the clean sensor stays silent and R-4.0-01 PASSes on it."""
    found = _verdicts(run_once("sim://?address=b", keyword="test_foreign_addresses_are_ignored"))
    assert found["R-4.0-01"]["verdict"] == "PASS"
    details = " ".join(f["detail"] for f in found["R-4.0-01"]["findings"])
    assert "zAb!" in details, details


def test_answers_to_kept_queries_are_not_timed_as_replies(monkeypatch):
    """The lagopus sketch's answers to the ?!s it kept through its boot came 1.50 ms after
    the tool's 0!, '1<CR><LF>' here from the sim at '1': R-7.0-09 FAILed "1.50 ms, allowed
    >= 7.93 ms" on them (the sketch's own 7.67 ms replies hid it there). They answer no
    command of the tool's: not timed now, and the sim's 9 ms replies PASS."""
    boots_late(monkeypatch, 1.45)
    found = _verdicts(
        run_once(
            "sim://?faults=factory-address-not-zero",
            keyword="test_acknowledge_active or test_response_start_window",
        )
    )
    for rid in ("R-7.0-09", "R-7.0-10"):
        assert found[rid]["verdict"] == "PASS", (rid, found[rid]["findings"])
        detail = found[rid]["findings"][0]["detail"]
        assert "9.00..9.00 ms" in detail, detail


@pytest.fixture
def indexed_commands_without_bang(monkeypatch):
    """The nineteenth round's logger (lixpaulian/dacq's sdi12_dr at 0507134) builds ``aMn!``
    and ``aCn!`` as ``0M1``: no '!' (``buff[3] = use_crc ? ... : '\\0'``). Unanswered, it sends
    the same text again 50 ms later without a break, as any retry."""
    from conformance.tool_recorder import engine

    encode = engine.encode_7e1
    indexed = re.compile(r"^.[MC][1-9]!$")
    monkeypatch.setattr(
        engine, "encode_7e1", lambda text: encode(text[:-1] if indexed.match(text) else text)
    )


def test_retries_of_a_command_without_its_bang_are_not_one_command_r_7_0_13(
    indexed_commands_without_bang,
):
    """The wire shows ``0M1`` then ``0M1`` again after the retry's marking: R-7.0-13 FAILed
    "marking between command characters: 50.00 ms [in 0M10M10M1]", as if the tries were one
    command. A sensor drops a partial command after 8.33 ms of marking (App. B): whether that
    gap is inside a command the wire does not say (INCONCLUSIVE); the missing '!' is
    R-4.4-04's FAIL either way, and the golden recorder's own gaps still PASS."""
    keyword = "test_every_basic_command_and_family or test_command_text or test_character_timing"
    found = _verdicts(run_once("sim", role="recorder", keyword=keyword))
    assert found["R-4.4-04"]["verdict"] == "FAIL", found["R-4.4-04"]["findings"]
    assert "0M10M1" in found["R-4.4-04"]["findings"][0]["detail"]
    gaps = found["R-7.0-13"]
    assert gaps["verdict"] == "INCONCLUSIVE", gaps["findings"]
    assert "before any '!'" in gaps["findings"][0]["detail"], gaps["findings"]


@pytest.fixture
def acknowledges_before_data(monkeypatch):
    """The golden recorder, ``a!`` sent to the sensor before its first D command, after ttt or
    the service request: the twentieth round's logger (jmpmscorp/esp-sdi-12) makes its device
    handle with ``sdi12_new_dev``, which sends ``a!``, the first time it meets an address."""
    from conformance.tool_recorder.engine import ToolRecorder

    collect = ToolRecorder.collect

    def acknowledging(self, m, **kw):
        if m.count and not m.data:
            self.acknowledge(m.command.address)
        return collect(self, m, **kw)

    monkeypatch.setattr(ToolRecorder, "collect", acknowledging)


def test_an_acknowledge_between_a_measurement_and_its_data_is_no_collection_given_up(
    acknowledges_before_data,
):
    """R-4.4.7-08 FAILed "read none of the 5 values", R-4.4.8-05 "stopped after the reply with
    0 of 3 values", R-4.4-02 "logged 5 value(s), the sensor sent 0", R-4.4.5-05 "no aD0! after
    the measurement" on a recorder that read every value (the sensor keeps its data until
    another measurement, 4.4.5 and 4.4.7)."""
    keyword = (
        "test_concurrent_measurements or test_data_continuation or "
        "test_logged_values_are_the_values_sent or test_waiting_for_the_service_request"
    )
    found = _verdicts(run_once("sim", role="recorder", keyword=keyword))
    for rid in ("R-4.4.7-08", "R-4.4.8-05", "R-4.4-02", "R-4.4.5-05"):
        assert found[rid]["verdict"] == "PASS", (rid, found[rid]["findings"])


@pytest.fixture
def concurrent_answered_unkn(monkeypatch):
    """The simulated sensor answering every aC!-type command 'aUNKN' (joembedded's
    SDI_12_slave sketch, twentieth round: concurrent measurement taken out, its parser's
    ``default: responseStr = "UNKN"``)."""
    from conformance.protocol.commands import Kind

    usual = FaultSet.rewrite

    def rewrite(self, reply):
        cmd = reply.command
        if cmd is not None and cmd.kind is Kind.CONCURRENT and reply.kind is ReplyKind.START:
            return replace(reply, kind=ReplyKind.CHATTER, body=cmd.address + "UNKN", crc=False)
        return usual(self, reply)

    monkeypatch.setattr(FaultSet, "rewrite", rewrite)


def test_text_to_ac_is_no_support_r_4_4_7_08(concurrent_answered_unkn):
    """R-4.4.7-08 (a v1.2+ sensor supports aC!) PASSed "aC! answered '0UNKN<CR><LF>'" and
    R-4.4.7-02 (aC! starts a real measurement) "conforms (2 checked: 0C!, 0CC!)" on a sensor
    whose answer says it does not know the command. Text of its own is no support
    (judges.support): R-4.4.7-08 FAILs, R-4.4.7-02 has no measurement to judge."""
    found = _verdicts(
        run_once("sim://", keyword="test_concurrent_reply or test_concurrent_supported")
    )
    assert found["R-4.4.7-08"]["verdict"] == "FAIL", found["R-4.4.7-08"]["findings"]
    assert "not supported: 0C! -> '0UNKN" in found["R-4.4.7-08"]["findings"][0]["detail"]
    assert found["R-4.4.7-02"]["verdict"] == "INCONCLUSIVE", found["R-4.4.7-02"]["findings"]
    assert found["R-4.4.7-01"]["verdict"] == "FAIL"  # the form, as before


def test_text_to_acc_is_no_crc_support_r_4_4_12_01(concurrent_answered_unkn):
    """R-4.4.12-01 (a v1.3 sensor supports aMC!, aCC!, ...) PASSed "answered (CRC variants
    are mandatory from v1.3)" with aCC! among the replies, answered '0UNKN'. Plain aMC!/aCC!
    are always defined: text to one is no support. (Text to an undefined aMCn!/aCCn! group
    or to an aRCn! stays the form rules' business: R-4.4.9-02, R-4.4.8.1-03.)"""
    found = _verdicts(run_once("sim://", keyword="test_crc_commands_supported"))
    rule = found["R-4.4.12-01"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    assert "0CC! -> '0UNKN" in " ".join(f["detail"] for f in rule["findings"]), rule["findings"]


@pytest.fixture
def wildcard_answered_late(monkeypatch):
    """The simulated sensor as the twenty-first round's Arduino Due sensor (ShadmanKroos'
    ENG-20009 sketch, docs/kit.md): no ``a!``, and any command starting with '?' answered
    with its address 100 ms after the '!', deaf meanwhile (the sketch's ``delay(100)`` in
    ``SDI12Send``) and through a break (a blocked firmware hears none)."""
    from conformance.emulator.replies import Reply
    from conformance.emulator.sensor import SensorEmulator

    late = []
    usual_command, usual_break = SensorEmulator._command, SensorEmulator.on_break

    def _command(self, text, start, end, foreign):
        if text.startswith("?") and text != "?!" and start >= self._quiet_until:
            sent = self._send(Reply(ReplyKind.ADDRESS, self.address), end + 0.1)
            late.append(sent)
            self._quiet_until = max(self._quiet_until, sent.end)
            return
        usual_command(self, text, start, end, foreign)

    def on_break(self, start, end):
        keep = [t for t in self._tx.queue if t.sent == 0 and any(t is x for x in late)]
        usual_break(self, start, end)
        self._tx.queue += [t for t in keep if not any(t is q for q in self._tx.queue)]

    monkeypatch.setattr(SensorEmulator, "_command", _command)
    monkeypatch.setattr(SensorEmulator, "on_break", on_break)
    usual = FaultSet.rewrite
    monkeypatch.setattr(
        FaultSet,
        "rewrite",
        lambda self, reply: None if reply.kind is ReplyKind.ACKNOWLEDGE else usual(self, reply),
    )


def test_a_late_reply_to_the_probe_before_is_no_refused_address_r_4_3_03(wildcard_answered_late):
    """The '0' for the ?I! probe came 14 ms after the 0A1! sent next, which the sensor never
    heard: R-4.3-03 FAILed "refused or lost address(es) 1". A change that did not take, whose
    reply may be the command before's late one, is asked again (``address_change.
    may_be_late_reply_to``): the sweep goes on, and with ?! naming each new address and the
    move back from it answered (it answers no a!) R-4.3-03 PASSes."""
    data = run_once(
        "sim://",
        keyword="test_identification or test_wildcard_with_other_commands or test_address_range",
    )
    rule = _verdicts(data)["R-4.3-03"]
    assert rule["verdict"] == "PASS", rule["findings"]
    assert "?! named the address" in rule["findings"][0]["detail"], rule["findings"]


def test_a_refusal_after_an_unanswered_probe_still_fails_r_4_3_03(wildcard_answered_late):
    """Asked again, a sensor whose change reply names its old address still says so: the
    re-ask turns no such reply into anything else (fault address-change-wrong-reply, the
    same late probe before the sweep's first change)."""
    data = run_once(
        "sim://?faults=address-change-wrong-reply",
        keyword="test_identification or test_wildcard_with_other_commands or test_address_range",
    )
    rule = _verdicts(data)["R-4.3-03"]
    assert rule["verdict"] == "FAIL", rule["findings"]


@pytest.fixture
def data_never_answered(monkeypatch):
    """The simulated sensor silent to every aDn! (the twenty-first round's Due sketch has
    a D1 branch and no D0)."""
    usual = FaultSet.rewrite
    monkeypatch.setattr(
        FaultSet,
        "rewrite",
        lambda self, reply: None if reply.kind is ReplyKind.DATA else usual(self, reply),
    )


def test_a_silent_d0_is_no_values_returned_r_4_4_8_04(data_never_answered):
    """R-4.4.8-04 (aD0! returns at least one value when values were announced) PASSed
    "conforms (12 checked)" with every aD0! unanswered. Its silence is R-4.4.8-01's FAIL;
    whether D0 returns values is unread: INCONCLUSIVE, and R-4.4.8-03 still FAILs."""
    found = _verdicts(run_once("sim://", keyword="test_announced_values_delivered"))
    assert found["R-4.4.8-04"]["verdict"] == "INCONCLUSIVE", found["R-4.4.8-04"]["findings"]
    assert "no reply to 0D0!" in found["R-4.4.8-04"]["findings"][0]["detail"]
    assert found["R-4.4.8-03"]["verdict"] == "FAIL"


def _answer_with_ident(monkeypatch, kind: Kind) -> None:
    """The simulated sensor answering every command of ``kind`` with its aI! identification,
    as a parser that reads only the 'I' does."""
    from conformance.emulator.sensor import SensorEmulator
    from conformance.protocol.commands import parse_command

    usual = SensorEmulator._dispatch

    def _dispatch(self, cmd, at):
        if cmd.kind is kind:
            cmd = parse_command(f"{cmd.address}I!")
        usual(self, cmd, at)

    monkeypatch.setattr(SensorEmulator, "_dispatch", _dispatch)


@pytest.fixture
def identify_measurement_answered_with_ident(monkeypatch):
    """aI<m>! answered with the aI! identification (the twenty-first round's Due sketch:
    ``input.charAt(1) == "I"`` answers any 0I...!)."""
    _answer_with_ident(monkeypatch, Kind.IDENTIFY_MEASUREMENT)


def test_the_identification_to_aim_is_no_answer_r_6_1_01(identify_measurement_answered_with_ident):
    """R-6.1-01 (a v1.4 sensor answers aIM!, aIMC!, ...) PASSed "answered" with the sensor's
    aI! text to each; R-6.1-02 FAILed the form. That text can be no atttn: not served."""
    found = _verdicts(run_once("sim://", keyword="test_identify_measurement_answered"))
    rule = found["R-6.1-01"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    assert "answered with its aI! identification" in rule["findings"][0]["detail"]


def test_identify_measurement_replies_still_pass_r_6_1_01():
    found = _verdicts(run_once("sim://", keyword="test_identify_measurement_answered"))
    assert found["R-6.1-01"]["verdict"] == "PASS", found["R-6.1-01"]["findings"]


@pytest.fixture
def metadata_answered_with_ident(monkeypatch):
    """aI<m>_nnn! answered with the aI! identification (outside31: a test slave on
    EnviroDIY's slave API, whose parser reads only the 'I')."""
    _answer_with_ident(monkeypatch, Kind.METADATA)


def test_the_identification_to_a_metadata_command_is_no_record_r_6_2_01(
    metadata_answered_with_ident,
):
    """R-6.2-01 (the sensor serves aIM_nnn! as a metadata command) PASSed "conforms (30
    checked)" with the sensor's aI! text to each, while R-6.2-02 FAILed their form: the
    command was never served as metadata. Now FAIL, naming the identification."""
    found = _verdicts(run_once("sim://", keyword="test_parameter_metadata"))
    rule = found["R-6.2-01"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    assert any("answered with its aI! identification" in f["detail"] for f in rule["findings"])
    assert found["R-6.2-02"]["verdict"] == "FAIL"


def test_metadata_records_still_pass_r_6_2_01():
    found = _verdicts(run_once("sim://", keyword="test_parameter_metadata"))
    assert found["R-6.2-01"]["verdict"] == "PASS", found["R-6.2-01"]["findings"]


#: A recorder harness that sends ``aM0!`` after each job's break, then sleeps for the uint32_t
#: milliseconds its firmware read from the missing reply (the twenty-second round's logger).
_SLEEPS_FOREVER = (
    PRELUDE
    + r"""
text, sent, deadline = "", 0, 0
for line in sys.stdin:
    word, *f = line.split()
    if word == "bye":
        break
    if word == "hello":
        say("hello 1 sleeps-forever")
    elif word == "job":
        now, text, sent = int(f[0]), f[2][0] + "M0!", 0
        say(f"brk {now} {now + 13000}")
    elif word == "break":
        say(f"tx {int(f[1]) + 8000} {wire(text[0]):02x}")
    elif word == "sent":
        sent += 1
        end = int(f[1])
        if sent < len(text):
            say(f"tx {end} {wire(text[sent]):02x}")
        else:
            deadline = end + 4289639296000
            say(f"wait {deadline}")
    else:  # a reply heard, or the sleep's end: sleep on (a new job starts the next command)
        say(f"wait {max(deadline, int(f[1]) + 1)}")
"""
)


def test_a_recorder_asleep_for_49_days_is_judged_not_stopped_r_7_2_01(tmp_path):
    """``wait 4289644352000`` stopped the run, ERROR and INCOMPLETE; the job now ends at its
    budget and the recorder is judged on what it sent: R-7.2-01 FAILs (aM0! unanswered, never
    sent again), the rules about the job that never ended stay undecided."""
    import sys

    harness = tmp_path / "sleeps.py"
    harness.write_text(_SLEEPS_FOREVER)
    found = run_once(f"exec:{sys.executable} {harness}", role="recorder", keyword="test_retries")
    assert found["summary"]["verdict"] == "NON-COMPLIANT", found["summary"]
    rules = _verdicts(found)
    assert rules["R-7.2-01"]["verdict"] == "FAIL", rules["R-7.2-01"]["findings"]
    assert any("0M0!" in f["detail"] for f in rules["R-7.2-01"]["findings"])


@pytest.fixture
def plain_measure_answered_very_late(monkeypatch):
    """The simulated sensor as the twenty-first round's Due sketch answers ``0M!`` (docs/kit.md):
    its 190 ms ``performReading()`` and ``delay(100)`` put the start reply 280 ms after the
    '!', past the tool's first retry sequence and before the next one's break; deaf meanwhile,
    and its queued reply kept through a break (a blocked firmware hears none)."""
    from conformance.emulator.sensor import SensorEmulator
    from conformance.protocol.commands import Kind

    late = []
    usual_send, usual_break = SensorEmulator._send, SensorEmulator.on_break

    def _send(self, reply, at):
        cmd = reply.command
        plain = cmd is not None and cmd.kind is Kind.MEASURE and cmd.group == 0 and not cmd.crc
        if reply.kind is not ReplyKind.START or not plain:
            return usual_send(self, reply, at)
        sent = usual_send(self, reply, at + 0.28)
        if sent is not None:
            late.append(sent)
            self._quiet_until = max(self._quiet_until, sent.end)
        return sent

    def on_break(self, start, end):
        keep = [t for t in self._tx.queue if t.sent == 0 and any(t is x for x in late)]
        usual_break(self, start, end)
        self._tx.queue += [t for t in keep if not any(t is q for q in self._tx.queue)]

    monkeypatch.setattr(SensorEmulator, "_send", _send)
    monkeypatch.setattr(SensorEmulator, "on_break", on_break)


def test_a_reply_between_retry_sequences_is_no_unanswered_command_r_4_4_01(
    plain_measure_answered_very_late,
):
    """'00023' to 0M!, 280 ms late, came after the first retry sequence's last window and
    before the next sequence's break: the view kept it in no attempt (the engine has it as the
    next try's stray), so R-4.4-01 FAILed "no reply although it is a basic command: 0M!"
    (docs/kit.md, twenty-first round, hedged "a consequence of R-7.0-10"). The view now keeps
    it as the retry's stray (view.rebuilt_records), and the rule is INCONCLUSIVE naming it."""
    found = _verdicts(run_once("sim://", keyword="test_every_basic_command_is_answered"))
    row = found["R-4.4-01"]
    assert row["verdict"] == "INCONCLUSIVE", row["findings"]  # FAIL before
    details = " ".join(f["detail"] for f in row["findings"])
    assert "0M! -> late '00023<CR><LF>'" in details, details
    assert "no reply" not in details, details


def test_a_command_truly_unanswered_beside_a_late_one_still_fails_r_4_4_01(
    plain_measure_answered_very_late,
):
    """A late 0M! leaves the silence of the rest to FAIL R-4.4-01: only the silent ones are
    listed (undefined-measure-silent: 0M3!.. never answered)."""
    found = _verdicts(
        run_once("sim://?faults=undefined-measure-silent", keyword="test_every_basic_command")
    )
    row = found["R-4.4-01"]
    assert row["verdict"] == "FAIL", row["findings"]
    details = " ".join(f["detail"] for f in row["findings"])
    assert "no reply although it is a basic command" in details and "0M3!" in details, details
    assert "0M!;" not in details and not details.rstrip().endswith("0M!"), details


def test_a_sensor_that_answers_no_a_is_not_reported_unrestored(a_never_answered, tmp_path):
    """The twenty-third round's Due sensor (no a!, aAb! answered): the address sweep moved it
    to '1' and back ('0' to 1A0!); its closing restore sent 1A0! again to a sensor at '0' and
    reported "COULD NOT restore the address ... (tried moving it back from 1)", and the refused
    0A$! "... (tried moving it back from $)", though ?! answered '0' throughout."""
    data = run_into(tmp_path, "sim://", keyword="test_address_range")
    notes = data["dut"]["address_notes"]
    assert notes and not any("COULD NOT" in note for note in notes), notes
    # the sweep goes on to '9' (its ?! and move-back replies show each address): the last
    assert any("moved back to '0' by its reply to 9A0!" in note for note in notes), notes
    assert any("?! answered '0'" in note for note in notes), notes
    tool = []
    for line in (tmp_path / "transcript.jsonl").read_text().splitlines():
        if '"origin": "tool"' in line and '"kind": "char"' in line:
            tool.append(chr(json.loads(line)["wire"] & 0x7F))
    sent = re.findall(r"[^!]*!", "".join(tool))
    first = sent.index("1A0!")
    assert "1A0!" not in sent[first + 1 :], sent[first:]  # once answered '0', never again


def test_a_sensor_that_answers_no_a_is_judged_on_its_other_replies_r_4_3_03(
    a_never_answered, tmp_path
):
    """The twenty-third round's Due sensor takes every address 0-9 and answers only ?! and
    aAb!: the sweep stopped after '1' (its move back could not be checked with a!) and
    R-4.3-03 stayed INCONCLUSIVE, though its reply to 1A0! showed it heard a command at '1'.
    Now ?! naming each new address and the move back answered from there are the proof, and
    the sweep goes on to '9'."""
    data = run_into(tmp_path, "sim://", keyword="test_address_range")
    rule = _verdicts(data)["R-4.3-03"]
    assert rule["verdict"] == "PASS", rule["findings"]
    detail = rule["findings"][0]["detail"]
    assert "1, 2, 3, 4, 5, 6, 7, 8, 9: ?! named the address" in detail, detail
    assert not any("COULD NOT" in note for note in data["dut"]["address_notes"])
    tool = []
    for line in (tmp_path / "transcript.jsonl").read_text().splitlines():
        if '"origin": "tool"' in line and '"kind": "char"' in line:
            tool.append(chr(json.loads(line)["wire"] & 0x7F))
    sent = re.findall(r"[^!]*!", "".join(tool))
    for b in "123456789":  # each move followed by ?! and the move back from there
        at = sent.index(f"0A{b}!")
        assert "?!" in sent[at:] and f"{b}A0!" in sent[at:], (b, sent[at:])


def test_a_sensor_that_answers_no_a_and_stays_put_is_no_r_4_3_03_pass(a_never_answered):
    """Its replies alone are no proof: one that answers 0A1! with '1' but keeps '0' (fault
    address-change-not-applied) names '0' to ?!, so the silence of a! stays no evidence and
    R-4.3-03 stays INCONCLUSIVE, never PASS."""
    data = run_once("sim://?faults=address-change-not-applied", keyword="test_address_range")
    rule = _verdicts(data)["R-4.3-03"]
    assert rule["verdict"] == "INCONCLUSIVE", rule["findings"]


#: A recorder harness that behaves as the twenty-sixth round's STM32 HAL logger does
#: (HarveyBates/stm32-projects, docs/kit.md; not its code): each command goes out with the
#: NUL of its C string; the USART stays swapped after a receive that filled its buffer, so
#: the next command leaves on the other pin (its break on the line, its characters not);
#: ``aM!`` is followed at once by ``aD0!``..``aD8!`` until as many signs as ``n`` came.
_SENDS_ITS_NUL = (
    PRELUDE
    + ASK
    + r"""
now, swapped = 0, False

def idle(until):
    while now < until and ask(f"wait {until}")[0] == "char":
        pass

def query(text, size):
    global swapped
    ask(f"brk {now} {now + 13000}")
    idle(now + 9000)
    for c in text + "\0":
        if swapped:
            idle(now + 8333)
        else:
            ask(f"tx {now} {wire(c):02x}")
    swapped, got, deadline = True, "", now + 381000
    while len(got) < size:
        word, f = ask(f"wait {deadline}")
        if word != "char" or now > deadline:
            swapped = False
            break
        got += chr(int(f[2], 16) & 0x7F)
    return got

sys.stdin.readline()  # hello
word, f = ask("hello 1 sends-its-nul")
cmds = f[2:] if f[1] == "measure" else []
for cmd in cmds if cmds and all(c[1:] == "M!" for c in cmds) else []:
    n = query(cmd, 7)[4:5]
    data = ""
    for i in range(9):
        data += query(f"{cmd[0]}D{i}!", 75)
        if n.isdigit() and data.count("+") + data.count("-") == int(n):
            break
    say(" ".join(["log", cmd] + re.findall(r"[+-][0-9.]+", data)))
say("done" if cmds and all(c[1:] == "M!" for c in cmds) else "cannot aM! jobs only")
sys.stdin.readline()  # bye
"""
).replace("import sys", "import re\nimport sys", 1)


@pytest.mark.slow
def test_a_recorder_that_sends_each_command_with_its_nul_is_judged_r_4_4_5_05(tmp_path):
    """The STM32 HAL logger's commands (``0M!<NUL>``) were no commands to the view, though the
    played sensor answered them: its measurements went unjudged ("nothing was observed").
    Now the flow is judged: its aD0!, sent on the other pin, never reached the line, and its
    aD1! 0.44 s after ``00023`` (no service request, ttt 2 s) FAILs R-4.4.5-04 and R-4.4.5-05
    (which PASSed "aD0! within 0.5 s" on an aD1!: tests/judges/recorder); the NULs still
    FAIL R-4.2-01 and R-4.4-04."""
    import sys

    harness = tmp_path / "sends_its_nul.py"
    harness.write_text(_SENDS_ITS_NUL)
    found = run_once(
        f"exec:{sys.executable} {harness}",
        role="recorder",
        keyword="test_waiting_for_the_service_request or test_command_text",
    )
    rules = _verdicts(found)
    assert rules["R-4.2-01"]["verdict"] == rules["R-4.4-04"]["verdict"] == "FAIL"
    assert rules["R-4.3-01"]["verdict"] == "PASS", rules["R-4.3-01"]["findings"]
    waited = rules["R-4.4.5-05"]
    assert waited["verdict"] == "FAIL", waited["findings"]
    assert any("0D1!, not aD0!" in f["detail"] for f in waited["findings"])
    assert rules["R-4.4.5-04"]["verdict"] == "FAIL", rules["R-4.4.5-04"]["findings"]


@pytest.fixture
def drops_every_mc(monkeypatch):
    """The golden recorder, every aMC! dropped after its valid ``atttn`` reply: no wait, no
    data command, nothing logged (R3 IoT's Zephyr SDI-12 master, twenty-seventh round,
    docs/kit.md: it parses the reply to aMC! as if it carried a CRC and rejects it)."""
    from conformance.tool_recorder.engine import ToolRecorder

    measure = ToolRecorder.measure

    def dropping(self, command, *, collect=True, wait="auto"):
        if command.returns_crc and command.kind is Kind.MEASURE:
            return measure(self, command, collect=False, wait="none")
        return measure(self, command, collect=collect, wait=wait)

    monkeypatch.setattr(ToolRecorder, "measure", dropping)


def test_a_measurement_dropped_after_its_reply_is_not_logged_as_sent(drops_every_mc):
    """'logged as sent' counted the dropped aMC! (nothing asked for, nothing logged) as a
    check of R-4.4-02; the drop itself is R-4.4.5-05's FAIL in the families scenario."""
    found = _verdicts(run_once("sim", role="recorder", keyword=FLOW_CASES))
    logged = " ".join(f["detail"] for f in found["R-4.4-02"]["findings"])
    assert "0MC!" not in logged, logged
    assert found["R-4.4-02"]["verdict"] == "PASS", found["R-4.4-02"]["findings"]
    waited = found["R-4.4.5-05"]
    assert waited["verdict"] == "FAIL", waited["findings"]
    assert any("0MC!" in f["detail"] and "no aD0!" in f["detail"] for f in waited["findings"])


def test_silent_numbered_groups_are_not_called_defined_r_4_4_8_03():
    """A mock sensor sketch on EnviroDIY's API (twenty-ninth round, docs/kit.md) answers no
    aMn!: R-4.4.8-03's N/A said "(every one is defined)" of groups that were never answered.
    Said of the answered ones only; a sensor that answers every group keeps the old text."""
    keyword = "test_undefined_group_leaves_no_old_values"
    silent = _verdicts(run_once("sim://?faults=undefined-measure-silent", keyword=keyword))
    [finding] = silent["R-4.4.8-03"]["findings"]
    assert finding["verdict"] == "N/A"
    assert finding["detail"] == "no aMn! group answers 'a0000' (those answered are defined)"
    assert "(every one is defined)" not in finding["detail"]


@pytest.fixture
def hung_by_an_early_command(monkeypatch):
    """The simulated sensor hung as the uOS++ SDI-12 sensor is (twenty-ninth round,
    docs/kit.md): a character heard less than 8.33 ms after a break (R-7.0-05's probe, a
    command 2 ms after one) leaves it deaf to characters and breaks for 5 s (its protocol
    thread waits for a marking its '!' interrupt switched off, until the 5 s virtual
    watchdog resets the board)."""
    from conformance.emulator.sensor import SensorEmulator
    from conformance.protocol.timing import MARKING_AFTER_BREAK

    on_char, on_break = SensorEmulator.on_char, SensorEmulator.on_break

    def hear(self, wire, start, end):
        if start < getattr(self, "_hung_until", float("-inf")):
            return
        if self._break_end is not None and start - self._break_end < MARKING_AFTER_BREAK:
            self._hung_until = start + 5.0
            return
        on_char(self, wire, start, end)

    def brk(self, start, end):
        if start >= getattr(self, "_hung_until", float("-inf")):
            on_break(self, start, end)

    monkeypatch.setattr(SensorEmulator, "on_char", hear)
    monkeypatch.setattr(SensorEmulator, "on_break", brk)


WAKE_CASES = "test_marking_after_break or test_ready_within_100ms_of_break"


def test_a_sensor_hung_by_an_early_command_is_not_failed_for_a_slow_wake_r_7_0_07(
    hung_by_an_early_command,
):
    """The uOS++ sensor answered R-7.0-05's probes as due (silent to the command 2 ms after
    the break), then nothing for 5 s: R-7.0-07 FAILed "no reply on the first transmission
    although the command began 90.00 ms after the break" on that hang, with no control. The
    case now sends a! the usual way after a silent probe: unanswered too, R-7.0-07 is not
    decided on the silence (slow-wake, its control answered, still FAILs: the test above)."""
    rule = _verdicts(run_once("sim://", keyword=WAKE_CASES))["R-7.0-07"]
    assert rule["verdict"] == "INCONCLUSIVE", rule["findings"]
    detail = " ".join(f["detail"] for f in rule["findings"])
    assert "answered neither the probe nor the control 0!" in detail, detail


def test_a_sensor_slow_to_wake_still_fails_r_7_0_07_beside_r_7_0_05():
    """The control after a silent R-7.0-07 probe is answered by a sensor merely slow to
    wake (110 ms): the FAIL stands, with R-7.0-05's case run before it as above."""
    rule = _verdicts(run_once("sim://?faults=slow-wake", keyword=WAKE_CASES))["R-7.0-07"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    assert "no reply on the first transmission" in rule["findings"][0]["detail"]


SR_CASE = "test_data_after_service_request_without_break"


def test_an_early_reply_after_a_break_is_no_late_reply_to_the_try_before_r_7_1_02():
    """The uOS++ sensor answers every command 7.67..8.35 ms after it (R-7.0-09's FAIL) and
    leaves its receiver off after its service request: aD0! 9 ms after it and the retries
    went unheard, the try after a break was answered 7.7 ms after it, and R-7.1-02 was
    INCONCLUSIVE "answered only after its reply window ... met by the retry": a reply too
    soon for its try was taken for the try before's, begun 93 ms after that one. Only one
    begun within the 87 ms of a late start (from when it was due) is now; here the sensor
    replying early (response-too-early) and deaf after its service request FAILs."""
    found = _verdicts(
        run_once("sim://?faults=response-too-early,deaf-after-service-request", keyword=SR_CASE)
    )
    rule = found["R-7.1-02"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    assert rule["findings"][0]["detail"].endswith("no break: no reply")


def test_a_reply_met_by_the_retry_is_still_the_try_befores_r_7_1_02():
    """replies-after-retry answers 80 ms after each try, its reply held back by the retry on
    the line: still the first aD0!'s late reply, not decided (the matrix row's own)."""
    rule = _verdicts(run_once("sim://?faults=replies-after-retry", keyword=SR_CASE))["R-7.1-02"]
    assert rule["verdict"] == "INCONCLUSIVE", rule["findings"]
    assert "met by the retry" in rule["findings"][0]["detail"]


@pytest.fixture
def address_control_unheard(monkeypatch):
    """The a! sent like aA$! goes to '9', where nobody answers: the control is silent, and
    the address is checked again afterwards (the restore), as after the uOS++ sensor's
    unheard control (its receiver off for 100 ms after a reply)."""
    from conformance.sensor.session import SensorSession

    heard = SensorSession.heard_probe

    def probe(self, text, *, control_address=None):
        return heard(self, text, control_address="9")

    monkeypatch.setattr(SensorSession, "heard_probe", probe)


def test_an_unanswered_address_control_is_the_evidence_it_cites_r_4_3_04(address_control_unheard):
    """R-4.3-04's "the a! sent like aA$! ... got no reply" cited the last exchange of the
    attempt, the restore's a! answered '0<CR><LF>' (uOS++ sensor, twenty-ninth round): the
    evidence said the opposite of the detail. It cites the control now."""
    rule = _verdicts(run_once("sim://", keyword="test_address_range"))["R-4.3-04"]
    [finding] = rule["findings"]
    assert finding["verdict"] == "INCONCLUSIVE", finding
    assert "got no reply" in finding["detail"]
    [line] = finding["evidence"]
    assert line.endswith("9! -> '(silence)'"), line


def test_no_control_sent_is_not_called_unanswered_r_4_3_04():
    """replies-after-retry answers no one-shot a! in its window (every reply 80 ms late), so
    no marking is found and aA$! goes without a control: "the a! sent like aA$! ... got no
    reply" spoke of an a! never sent (and cited the restore's, answered)."""
    rule = _verdicts(run_once("sim://?faults=replies-after-retry", keyword="test_address_range"))
    [finding] = rule["R-4.3-04"]["findings"]
    assert finding["verdict"] == "INCONCLUSIVE", finding
    assert "no one-shot a! after a break was answered" in finding["detail"], finding["detail"]
    assert finding["evidence"] == []


#: The thirtieth round (docs/kit.md): an ESP-IDF logger library (K0I05/ESP32-S3_SDI12's
#: esp_sdi12_master, MIT) behind the C kit. A look-alike of its ways, not its code: every
#: command a 12.5 ms break, 8.33 ms of marking and the command, the reply read up to its CR
#: within 917 ms from what the UART buffered since the last read (so a service request heard
#: while it sleeps ttt + 0.5 s is read as aD0!'s reply, "a<CR>", and taken for an abort: the
#: whole measurement is tried again, three times); ttt kept in 8 bits (260 s is 4 s); each
#: value but the last loses its last character to an off-by-one in the token scan.
_ESP_MASTER = (
    PRELUDE
    + ASK
    + r"""
now, pending = 0, ""

def hear(until, keep=True):
    global pending
    while now < until:
        word, f = ask(f"wait {until}")
        if word != "char":
            break
        if keep:
            pending += chr(int(f[2], 16) & 0x7F)

def command(text):
    global pending
    ask(f"brk {now} {now + 12500}")
    hear(now + 8333, keep=False)
    for c in text:
        ask(f"tx {now} {wire(c):02x}")
    got, pending, deadline = pending, "", now + 916670
    while "\r" not in got and now < deadline:
        word, f = ask(f"wait {deadline}")
        if word != "char":
            break
        got += chr(int(f[2], 16) & 0x7F)
    hear(now + 183000, keep=False)  # the read's last 100 ms, then the flush
    hear(now + 90000)  # buffered for the next read
    return got[: got.index("\r")] if "\r" in got else None

def values(reply):
    tokens = re.findall(r"[+-][^+-]*", reply)
    return [t[:-1] for t in tokens[:-1]] + tokens[-1:]

def measure(cmd):
    for _ in range(3):
        reply = command(cmd)
        if reply and reply[0] == cmd[0] and reply[1:4].isdigit():
            ttt, n = int(reply[1:4]) % 256, int(reply[4:] or 0)
            hear(now + ttt * 1000000 + 500000)
            got = []
            for i in range(10):
                data = command(f"{cmd[0]}D{i}!")
                if data is None or len(data) < 3:
                    break
                got += values(data)
                if len(got) >= n:
                    return got
        hear(now + 115000)
    return []

sys.stdin.readline()  # hello
word, f = ask("hello 1 esp-master-alike")
task, cmds = f[1], f[2:]
lacking = []
for cmd in cmds:
    if task in ("measure", "concurrent"):
        if re.fullmatch(r"\w[MC][1-9]?!", cmd):
            line = f"log {cmd}"
            for v in ["%.7g" % float(v) for v in measure(cmd)]:
                if len(line) + 1 + len(v) > 200:
                    say(line)
                    line = f"log {cmd}"
                line += " " + v
            say(line)
        else:
            lacking.append(cmd)
    else:
        command(cmd)
say("cannot " + " ".join(lacking) if lacking else "done")
sys.stdin.readline()  # bye
"""
).replace("import sys", "import re\nimport sys", 1)


@pytest.mark.slow
def test_a_logger_that_cuts_digits_is_not_told_its_absent_crc_excuses_nothing(tmp_path):
    """With a v1.3 declaration without CRC, R-4.4-02's FAIL on the values it logged wrong
    (digits cut off, nothing logged where a service request came) listed more measurements
    than its detail shows ("(+N more)") and so kept the "declared absent (aMC! ...) ... does
    not excuse it" note of the aMC! it was never asked for here: every command its tally
    names was declared present. The measurement flow's true FAILs stand: aD0! 4.8 s after
    ``02603`` (ttt 260 s kept in 8 bits) is R-4.4.5-04's."""
    import sys

    harness = tmp_path / "esp_master_alike.py"
    harness.write_text(_ESP_MASTER)
    declared = tmp_path / "esp.toml"
    declared.write_text('sdi12_version = "1.3"\n[recorder]\ncrc = false\n', encoding="utf-8")
    found = run_once(
        f"exec:{sys.executable} {harness}",
        role="recorder",
        keyword=FLOW_CASES,
        declaration=str(declared),
    )
    rules = _verdicts(found)
    logged = [f["detail"] for f in rules["R-4.4-02"]["findings"] if "digits cut off" in f["detail"]]
    assert logged and "more)" in logged[0], rules["R-4.4-02"]["findings"]
    assert not any("declared absent" in d for d in logged), logged
    waited = rules["R-4.4.5-04"]
    assert waited["verdict"] == "FAIL", waited["findings"]
    assert any("ttt=260" in f["detail"] for f in waited["findings"]), waited["findings"]


def test_a_sensor_that_answers_no_a_has_its_replies_framing_judged_r_4_3_01(a_never_answered):
    """The thirty-fourth round's ENG20009 Due sketch answers no a!, but its measurements at
    '0', and sends lines such as 'FINAL DATA @2<CR><LF>': the whole-run framing case asked a!
    alone whether the sensor was at its address, left R-4.3-01 undecided, and the rule PASSed
    on the exploration's checks. A measurement answered at the address shows it there (the
    sensor here starts its D replies with '1': INCONCLUSIVE "a! at it got no reply" at
    base-s69)."""
    found = _verdicts(run_once("sim://?faults=wrong-reply-address", keyword="test_reply_framing"))
    rule = found["R-4.3-01"]
    assert rule["verdict"] == "FAIL", rule["findings"]
    assert "not the address '0'" in rule["findings"][0]["detail"]
