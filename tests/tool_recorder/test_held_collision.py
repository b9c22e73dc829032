"""A character the bus held behind the tool's command is no reply to it (truth37).

On the harness bus a sensor frame planned inside one of the tool's characters goes out where
the tool's command ends, marked :data:`~conformance.transcript.COLLISION` (it wanted the line
while the tool had it). The view sets it aside as contention; the live read took it as the
reply, since it starts at the command's end: outside34's ENG20009 Due sketch's values line of
the ``aR0!`` before, due during the retry, "answered" 0R0! and R-4.4.8.1-01 PASSed on it.
"""

from __future__ import annotations

from conformance.harness.device import HarnessBus
from conformance.protocol.timing import CHAR_TIME
from conformance.sim.bus import Frame, SimLink
from conformance.tool_recorder import ToolRecorder
from conformance.tool_recorder.records import CONTENTION
from conformance.transcript import COLLISION, DUT, encode_7e1


class _HeldLine:
    """Plans ``text`` at the end of the first character it hears (the start of the tool's
    next one) and, as the firmware kit does, plans a frame that a character of the tool's
    overlaps again where that character ends: the line leaves at the command's end."""

    name = "held-line"

    def __init__(self, text: str) -> None:
        self.text, self.frames = text, []

    def on_break(self, start: float, end: float) -> None:
        self._after(end)

    def on_char(self, wire: int, start: float, end: float) -> None:
        if self.text and not self.frames:
            self.frames = [
                Frame(end + k * CHAR_TIME, w) for k, w in enumerate(encode_7e1(self.text))
            ]
            self.text = ""
        else:
            self._after(end)

    def _after(self, end: float) -> None:
        if self.frames and self.frames[0].start < end:
            shift = end - self.frames[0].start
            self.frames = [Frame(f.start + shift, f.wire) for f in self.frames]

    def next_frame(self) -> Frame | None:
        return self.frames[0] if self.frames else None

    def pop_frame(self) -> Frame:
        return self.frames.pop(0)


def test_a_line_held_to_the_commands_end_is_contention_not_its_reply():
    bus = HarnessBus()
    bus.attach(_HeldLine("0+21.72+45.50\r\n"))
    ex = ToolRecorder(SimLink(bus)).transact("0R0!")
    first = ex.attempts[0]
    held = [e for e in bus.transcript.events if e.origin == DUT][0]
    assert held.text == COLLISION and held.start == first.command_end
    assert first.reply_events == [] and first.reason.startswith(CONTENTION)  # "ok" before
    assert held in first.stray_events
    assert not ex.answered  # the line was never the reply of any try
