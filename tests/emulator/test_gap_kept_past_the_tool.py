"""A sensor's marking between its reply characters survives the tool talking over the reply.

The sim bus has one wire: a device character planned while the tool's character holds the
line goes out when it ends. Before truth19 the frames of the reply that fell due meanwhile
then went out back to back, so an ``inter-char-gap`` sensor (3 ms between characters) whose
late reply met the tool's retry (beside ``replies-after-retry``) showed 8.33 ms spacings it
never sends: R-4.1-01 PASSed on them, and the reply came back shuffled with the retry.
"""

from __future__ import annotations

import pytest

from conformance.emulator import default_profile
from conformance.emulator.replies import Reply, ReplyKind
from conformance.emulator.transmitter import Transmitter
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT
from tests.emulator.test_sensor import Rig

GAP = 3e-3


def test_the_rest_of_a_gapped_reply_moves_after_the_character_that_held_it() -> None:
    tx = Transmitter()
    item = tx.schedule(Reply(ReplyKind.DATA, "0+1.25+3.5"), 1.0, GAP)
    later = tx.schedule(Reply(ReplyKind.SERVICE_REQUEST, "0"), item.end + CHAR_TIME, GAP)
    tx.pop_frame()
    planned = item.frame_start(1)
    tx.line_taken_until(planned + 2e-3)  # a character of the tool's ends 2 ms into frame 1
    assert item.frame_start(1) == pytest.approx(planned + 2e-3, abs=1e-12)
    assert item.frame_start(2) - item.frame_start(1) == pytest.approx(CHAR_TIME + GAP)
    assert later.start >= item.end + CHAR_TIME  # what waited for it waits still
    assert tx.next_frame().start == item.frame_start(1)  # not the frame offered before


def test_a_reply_with_no_marking_is_left_as_planned() -> None:
    tx = Transmitter()
    item = tx.schedule(Reply(ReplyKind.DATA, "0+1.25"), 1.0, 0.0)
    start = item.start
    tx.line_taken_until(start + 5e-3)
    assert item.start == start  # the bus sends it back to back either way


def test_an_inter_char_gap_reply_the_tool_talks_over_keeps_its_gaps() -> None:
    rig = Rig(default_profile(), ("inter-char-gap",))
    rig.wake()
    rig.send("0I!")
    rig.wait(12e-3)  # the reply's first characters are out
    rig.send("0000")  # the tool talks over the rest of it
    rig.listen(timeout=1.0, idle=50e-3)
    dut = [e for e in rig.link.transcript.events if e.kind.name == "CHAR" and e.origin == DUT]
    assert len(dut) > 10
    spacings = [b.start - a.start for a, b in zip(dut, dut[1:], strict=False)]
    assert min(spacings) >= CHAR_TIME + GAP - 1e-9  # 8.33 ms (back to back) before truth19
