"""No look past the turnaround after a reply that closed its exchange at its CR LF (issue 22,
eff11): after ``a!``, ``aI!``, ``aD0!``, ``aR0!``, ``?!``, ``aAb!`` and metadata records no
rule reads what the sensor sends right after the LF, a compliant sensor has released the line
7.5 ms (+0.4) after it (R-7.0-11), and the turnaround (9 ms from the LF's stamp, never
earlier than its end on the wire) is already past that. The look (4.33 ms behind a link
stamped to 5 ms) stays where a rule does read on: after ``atttn`` (a service request may
follow at once, R-4.4.6-03; ``aIM!``, R-6.1-03), after extended, binary and unparsed
commands, after a reply that did not end with CR LF, and after anything the DUT sent past the
reply. A character that arrives during the turnaround still holds the transmission.

The sim link stands in for a real one with a 5 ms timing uncertainty, as in
``test_look_before_transmit.py``."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.protocol.commands import parse_command
from conformance.protocol.timing import CHAR_TIME, RELEASE_LINE, TOLERANCE
from conformance.tool_recorder.engine import ToolRecorder, closes_exchange
from conformance.tool_recorder.policy import Policy
from conformance.transcript import TOOL, EventKind
from tests.tool_recorder.test_scripted_sensor import Burst, ScriptedSensor, rig

UNCERTAINTY = 5e-3
TURNAROUND = Policy().turnaround
LOOK = CHAR_TIME + UNCERTAINTY - TURNAROUND  # 4.33 ms

#: commands whose one-line reply closes the exchange, with a reply the scripted sensor sends
CLOSED = {
    "0!": "0\r\n",
    "?!": "0\r\n",
    "0I!": "014MAKER   MODEL 1.0\r\n",
    "0D0!": "0+1.5\r\n",
    "0R0!": "0+1.5\r\n",
    "0A1!": "1\r\n",
    "0IM_001!": "0,PA,kPa;\r\n",
}
#: commands after whose reply the look stays
LOOKED_AFTER = {
    "0M!": "00011\r\n",
    "0M1!": "00001\r\n",
    "0V!": "00011\r\n",
    "0C!": "000101\r\n",
    "0IM!": "00011\r\n",
    "0XSET!": "0OK\r\n",
}


def _real_like(script: dict[str, str]) -> ToolRecorder:
    return _real_like_bursts({k: [v] for k, v in script.items()})


def _real_like_bursts(script: dict) -> ToolRecorder:
    master, _ = rig(ScriptedSensor({"0!": ["0\r\n"], **script}))
    master.link.info = replace(master.link.info, timing_uncertainty=UNCERTAINTY)
    return master


def _dut_end(master: ToolRecorder) -> float:
    return max(
        e.end
        for e in master.link.transcript.events
        if e.kind is EventKind.CHAR and e.origin != TOOL
    )


def _marking_before_next(master: ToolRecorder, first: str) -> float:
    """Send ``first`` (its reply read to its end), then ``a!`` without a break; the marking
    from the DUT's last character to the ``a!``'s start bit."""
    master.raw(first, break_first=True)
    last = _dut_end(master)
    ex = master.raw("0!", break_first=False)
    return ex.attempts[0].command_events[0].start - last


@pytest.mark.parametrize("command", sorted(CLOSED))
def test_after_a_closed_reply_the_tool_transmits_once_the_turnaround_is_over(command):
    """R-7.0-11: the next command goes out 9 ms after the LF, not 13.33 ms (it did)."""
    master = _real_like({command: CLOSED[command]})
    marking = _marking_before_next(master, command)
    assert marking == pytest.approx(TURNAROUND, abs=1e-12)
    assert marking >= RELEASE_LINE + TOLERANCE  # the sensor's 7.5 (+0.4) ms are left to it
    assert master.look_before_transmit() == 0.0  # after the a! reply too


@pytest.mark.parametrize("command", sorted(LOOKED_AFTER))
def test_after_a_reply_a_rule_reads_on_from_the_look_stays(command):
    """``atttn`` (a service request may follow at once), an extended command's reply (it
    may run on): the tool waits for a character sent back to back after the LF."""
    master = _real_like({command: LOOKED_AFTER[command]})
    marking = _marking_before_next(master, command)
    assert marking == pytest.approx(TURNAROUND + LOOK, abs=1e-12)
    assert marking == pytest.approx(CHAR_TIME + UNCERTAINTY, abs=1e-12)


def test_after_an_unparsed_command_the_look_stays():
    master = _real_like({"0I?!": "0?\r\n"})
    assert _marking_before_next(master, "0I?!") == pytest.approx(TURNAROUND + LOOK, abs=1e-12)


def test_after_a_reply_without_its_cr_lf_the_look_stays():
    """A reply the line's idle ended (no LF): the DUT may be in the middle of it."""
    master = _real_like({"0I!": "014MAKER"})
    master.raw("0I!", break_first=True)
    assert master.look_before_transmit() == pytest.approx(LOOK, abs=1e-12)


def test_a_character_right_after_the_lf_still_holds_the_transmission():
    """A trailing character sent back to back after the CR LF ends 8.33 ms after it, inside
    the turnaround: the command waits for the turnaround and the look after that one."""
    reply = Burst("014MAKER   MODEL 1.0\r\n")
    master = _real_like_bursts({"0I!": [[reply, Burst("X", at=reply.end_offset)]]})
    master.raw("0I!", break_first=True)
    master.link.wait_until(master.link.now() + 1e-3)  # the read stopped at the LF
    master.link.receive(master.link.now())
    ex = master.raw("0!", break_first=False)
    trailing = _dut_end_before(master, ex.attempts[0].command_events[0].start)
    start = ex.attempts[0].command_events[0].start
    assert start == pytest.approx(trailing + TURNAROUND + LOOK, abs=1e-12)


def test_a_service_request_after_a_closed_reply_brings_the_look_back():
    """What the DUT sends after the closed reply is no longer that reply's end: the look
    after it is kept."""
    master = _real_like_bursts({"0I!": [[Burst("0ident\r\n"), Burst("0\r\n", at=0.2)]]})
    ex = master.raw("0I!", break_first=True)
    command_end = ex.attempts[0].command_end
    master.link.wait_until(command_end + 0.2 + 3 * CHAR_TIME + 2e-3)
    master.link.receive(master.link.now())
    sr_end = _dut_end(master)
    assert sr_end == pytest.approx(command_end + 0.2 + 3 * CHAR_TIME, abs=1e-12)
    assert master.look_before_transmit() == pytest.approx(LOOK, abs=1e-12)
    brk = master.send_break()
    assert brk.start == pytest.approx(sr_end + TURNAROUND + LOOK, abs=1e-12)


def test_closes_exchange_needs_the_cr_lf_and_a_one_line_command():
    assert not closes_exchange(None, [])
    assert not closes_exchange(parse_command("0DB0!"), [])


def test_on_the_sim_nothing_changes():
    """No uncertainty: the turnaround covers a back-to-back frame and the look was 0 before."""
    master, _ = rig(ScriptedSensor({"0M!": ["00001\r\n"], "0I!": ["0ident\r\n"]}))
    master.raw("0M!", break_first=True)
    assert master.look_before_transmit() == 0.0
    master.raw("0I!", break_first=False)
    assert master.look_before_transmit() == 0.0


def _dut_end_before(master: ToolRecorder, at: float) -> float:
    return max(
        e.end
        for e in master.link.transcript.events
        if e.kind is EventKind.CHAR and e.origin != TOOL and e.end <= at
    )
