"""A late reply the next command's character held is still the late reply (truth19).

The replies-after-retry sensor beside slow-wake answered 0C9!'s 0D0! 80 ms after its last
try, while the tool's next command, 0IMC_001!, was on the line: the sim bus holds a sensor
frame that falls due under the tool's character to that character's end, so its '0' began
88.33 ms after the try, past the 87 ms a late start is believed within, and "0C9! 0D0!: no
reply to 0D0!" FAILed R-4.4.8-01 (``judges.late_before._due``). Hand-typed events.
"""

from __future__ import annotations

from conformance.judges.late_before import late_reply
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.records import NO_REPLY, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from tests.support.hand_events import chars

REPLY = "0+22.15+1013.2\r\n"


def _d0_then_identify(reply_at: float, next_at: float = 0.030) -> Exchange:
    """0D0! unanswered at 0 s; 0IMC_001! ``next_at`` s after it ended; ``REPLY`` beginning
    ``reply_at`` s after 0D0! ended, taken by 0IMC_001!'s first try."""
    sent = chars(TOOL, "0D0!", 0.0)
    end = sent[-1].end
    d0 = Exchange(cmds.parse_command("0D0!"), "0D0!", [Attempt(None, sent, [], NO_REPLY, end)])
    nxt = chars(TOOL, "0IMC_001!", end + next_at)
    got = chars(DUT, REPLY, end + reply_at)
    after = Exchange(
        cmds.parse_command("0IMC_001!"),
        "0IMC_001!",
        [Attempt(None, nxt, got, "invalid: bus contention", got[-1].end)],
    )
    d0.next_sent[:] = [after]
    return d0


def test_a_reply_held_to_the_end_of_the_tool_s_character_is_the_late_reply() -> None:
    held = 0.030 + 7 * CHAR_TIME  # the end of 0IMC_001!'s seventh character: 88.33 ms
    assert late_reply(_d0_then_identify(held)) == REPLY  # '' before: past 87 ms


def test_a_reply_begun_past_87_ms_on_its_own_is_not() -> None:
    """The same 88.33 ms where no character of the tool's ended then: not believed late."""
    assert late_reply(_d0_then_identify(0.030 + 7 * CHAR_TIME, next_at=0.034)) == ""
