"""A break played where it was sent (``SimBus.tool_break(duration, at)``): a recorded
recorder's break over a sensor's character still coming (the capture round trip's replay,
:mod:`conformance.recorder.replay_driver`) must begin where the recording has it, not after
the character the simulated bus commits whole, or the marking after it (R-7.0-06) reads short."""

from __future__ import annotations

import pytest

from conformance.protocol.timing import CHAR_TIME
from conformance.sim.bus import SimBus
from tests.tool_recorder.test_scripted_sensor import Babbler, tool_breaks


def test_r_7_0_06_a_break_at_a_time_inside_a_character_begins_there():
    bus = SimBus([Babbler(6)])  # type: ignore[list-item]
    at = 1.5 * CHAR_TIME  # inside the babbler's second character
    bus.advance(at)  # as RecordedRecorder's wait_until: that character is committed whole
    assert bus.clock.now == pytest.approx(2 * CHAR_TIME)
    brk = bus.tool_break(12e-3, at)
    assert (brk.start, brk.end) == (at, pytest.approx(at + 12e-3))
    assert tool_breaks(bus) == [brk]
    starts = [e.start for e in bus.transcript]
    assert starts == sorted(starts)  # the events stay in the order they began


def test_a_break_without_a_time_still_waits_for_the_character_in_progress():
    bus = SimBus([Babbler(6)])  # type: ignore[list-item]
    bus.advance(1.5 * CHAR_TIME)
    assert bus.tool_break(12e-3).start == pytest.approx(2 * CHAR_TIME)
