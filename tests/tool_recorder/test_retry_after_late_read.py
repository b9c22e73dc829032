"""A retry counts its gap from the silent try's first-character deadline, not from where a
real link's read of it ended (truth23).

Over RFC 2217 behind an echoing link with 2 ms of jitter on a loaded host, a silent read ran
15-25 ms past its 30 ms deadline; counted from there, each retry came back more than 87 ms
after its command, the break rule put a break in front of every one, and slow-wake's sensor
(110 ms after a break before it hears a start bit) heard none of the 9 tries of 0IM_000!:
R-6.2-05 FAILed "0IM_000! got no reply"."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.tool_recorder.engine import ToolRecorder
from conformance.tool_recorder.records import NO_REPLY
from tests.tool_recorder.test_scripted_sensor import ScriptedSensor, rig

UNCERTAINTY = 2.5e-3  # the echo-measured figure of the slow-wake bench run
OVERRUN = 30e-3  # how far past its deadline a silent read ended (15-25 ms seen, and load)


def _late_reads(master: ToolRecorder, overrun: float) -> None:
    """Make every silent read end ``overrun`` past its deadline, as a loaded host's did."""
    listen = master._listen

    def late(command_end, framing):
        reply, state, collided = listen(command_end, framing)
        if not reply:
            master.link.wait(overrun)
        return reply, state, collided

    master._listen = late  # type: ignore[method-assign]


def _silent_exchange(overrun: float):
    master, _ = rig(ScriptedSensor({}))
    master.link.info = replace(master.link.info, timing_uncertainty=UNCERTAINTY)
    _late_reads(master, overrun)
    return master, master.transact("0IM_000!", force_break=True)


def test_a_late_read_does_not_push_the_retry_behind_a_break():
    master, ex = _silent_exchange(OVERRUN)
    policy = master.policy
    assert all(a.reason == NO_REPLY for a in ex.attempts)
    first, second = ex.attempts[0], ex.attempts[1]
    assert second.break_event is None  # a retry, not a new break of its own
    gap = second.command_events[0].start - first.command_end
    assert gap == pytest.approx(policy.first_char_timeout + OVERRUN, abs=1e-9)
    # each sequence: one break, then its retries without one (R-7.2-03/04)
    breaks = [a.break_event is not None for a in ex.attempts]
    assert breaks == [True, False, False] * policy.sequences


def test_a_read_ended_at_its_deadline_keeps_the_retry_gap():
    master, ex = _silent_exchange(0.0)
    policy = master.policy
    first, second = ex.attempts[0], ex.attempts[1]
    gap = second.command_events[0].start - first.command_end
    assert gap == pytest.approx(policy.first_char_timeout + policy.retry_gap, abs=1e-12)
