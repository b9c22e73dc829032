"""The look before transmitting (issue 22, fifth round): on a link whose stamps come up to
``timing_uncertainty`` late the tool keeps the line quiet for the turnaround and that look
more after the DUT's last character before it transmits. The look is counted from the end of
the turnaround: a wait that already listened to a quiet line that long (a case's listening, a
read to its deadline, a retry's spacing) has done it, and adding it again made each such
transmission 5 ms later behind an RFC 2217 port (about 110 of them in a full run).

The look after the turnaround is what the turnaround leaves of a back-to-back character's frame
and the link's lateness (eff10): a DUT going on right after its CR LF has shown its next
character by CHAR_TIME + uncertainty after the last one's stamp, 13.33 ms behind RFC 2217,
where the tool waited 9 + 5 ms.

The sim link stands in for a real one with a 5 ms timing uncertainty, as in
``tests/sensor/test_mark_until.py``."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.engine import ToolRecorder, look_past_turnaround
from conformance.tool_recorder.policy import Policy
from conformance.transcript import TOOL, EventKind
from tests.tool_recorder.test_scripted_sensor import ScriptedSensor, rig, then_sr

UNCERTAINTY = 5e-3
TURNAROUND = Policy().turnaround
#: the look after the turnaround behind a link stamped to 5 ms: 8.33 + 5 - 9 ms
LOOK = CHAR_TIME + UNCERTAINTY - TURNAROUND


def _real_like(*devices: object) -> ToolRecorder:
    master, _ = rig(*devices)
    master.link.info = replace(master.link.info, timing_uncertainty=UNCERTAINTY)
    return master


def _reply_end(master: ToolRecorder) -> float:
    return max(
        e.end
        for e in master.link.transcript.events
        if e.kind is EventKind.CHAR and e.origin != TOOL
    )


def test_after_a_start_reply_the_turnaround_and_the_look_are_both_kept():
    """``atttn`` may be followed at once by a service request (ttt = 000, R-4.4.6-03): the
    tool looks for a character sent back to back after its LF before it transmits."""
    master = _real_like(ScriptedSensor({"0M!": ["00001\r\n"], "0D0!": ["0+1\r\n"]}))
    master.transact("0M!")
    last = _reply_end(master)
    ex = master.transact("0D0!")
    start = ex.attempts[0].command_events[0].start
    assert start == pytest.approx(last + TURNAROUND + LOOK, abs=1e-12)
    assert start - last == pytest.approx(CHAR_TIME + UNCERTAINTY, abs=1e-12)  # 13.33 ms


def test_the_look_covers_a_back_to_back_character_and_no_more():
    """A character that starts as the DUT's last one ends has arrived, at the latest, when
    the tool transmits; on the sim (no uncertainty) nothing is added to the turnaround, and
    a link looser than the turnaround's spare (0.67 ms) gets the rest of its uncertainty."""
    for u in (0.0, 0.5e-3, 2e-3, UNCERTAINTY, 15.409e-3):
        look = look_past_turnaround(u, TURNAROUND)
        assert look >= 0.0
        assert TURNAROUND + look >= CHAR_TIME + u - 1e-12
        assert TURNAROUND + look == pytest.approx(max(TURNAROUND, CHAR_TIME + u), abs=1e-12)
    assert look_past_turnaround(0.0, TURNAROUND) == 0.0


def test_after_listening_past_the_look_the_tool_transmits_at_once():
    """The look is over: the command goes out when the wait ends, not 5 ms later (it did)."""
    master = _real_like(ScriptedSensor({"0M!": ["00001\r\n"], "0I!": ["0ident\r\n"]}))
    master.transact("0M!")
    master.link.receive(master.link.now() + 0.2)  # a case's listening
    listened = master.link.now()
    ex = master.transact("0I!")  # past 87 ms of marking: a break first
    assert ex.attempts[0].break_event.start == pytest.approx(listened, abs=1e-12)


def test_after_a_wait_shorter_than_the_look_only_the_rest_of_it_is_listened():
    master = _real_like(ScriptedSensor({"0M!": ["00001\r\n"], "0I!": ["0ident\r\n"]}))
    master.transact("0M!")
    last = _reply_end(master)
    master.link.wait_until(last + TURNAROUND + 2e-3)
    ex = master.transact("0I!")
    start = ex.attempts[0].command_events[0].start
    assert start == pytest.approx(last + TURNAROUND + LOOK, abs=1e-12)


def test_a_retry_goes_out_at_its_retry_time():
    """No reply: the read ran to the first-character deadline, then the retry spacing; the
    retry is not pushed a look further (on the sim the read ends at its deadline: 30 ms, then
    25 ms of retry gap)."""
    master = _real_like(ScriptedSensor({}))
    ex = master.transact("0I!", force_break=True)
    first, second = ex.attempts[0], ex.attempts[1]
    policy = master.policy
    gap = second.command_events[0].start - first.command_end
    assert gap == pytest.approx(policy.first_char_timeout + policy.retry_gap, abs=1e-12)


def test_a_character_that_came_during_the_wait_still_holds_the_transmission():
    """A service request 0.5 s after the reply, while the case listened up to just after it:
    the break waits for the turnaround and the look after the request's last character."""
    master = _real_like(ScriptedSensor({"0M!": [then_sr("00011\r\n", 0.5)]}))
    master.transact("0M!")
    reply_end = _reply_end(master)
    master.link.wait_until(reply_end + 0.5 + 3 * CHAR_TIME + 2e-3)
    sr_end = _reply_end(master)
    assert sr_end > reply_end + 0.5
    assert master.link.now() < sr_end + TURNAROUND + LOOK
    brk = master.send_break()
    assert brk.start == pytest.approx(sr_end + TURNAROUND + LOOK, abs=1e-12)


def test_right_after_the_tools_own_break_there_is_no_look():
    master = _real_like(ScriptedSensor({"0!": ["0\r\n"]}))
    brk = master.send_break()
    assert master.look_before_transmit() == 0.0
    ex = master.raw("0!", break_first=False)
    marking = ex.attempts[0].command_events[0].start - brk.end
    assert marking == pytest.approx(master.policy.post_break_marking, abs=1e-12)
