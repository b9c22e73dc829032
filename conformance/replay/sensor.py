"""A recorded sensor: the device under test of a saved sensor-role run, played back.

Judging a saved run again means asking the same questions and getting the recorded answers.
The tool runs its cases as it did (same stimuli, in the same order: cases ask for what they
need, and exploration is derandomized), on a simulated bus where the emulator is replaced by
this device. It follows the tool's transmissions through the recording; every recorded reply is
offered once all the tool's recorded transmissions before it have been heard again, shifted by
how late or early the tool is now against the recording (on the sim the shift is zero, so the
replayed transcript is the recorded one). The judges then see what they saw the first time.

When the tool sends something the recording does not have next, the replay has diverged (the
tool changed, or the recording is not of this kind of run): :class:`ReplayDiverged` stops the
run with that said, instead of inventing answers.
"""

from __future__ import annotations

from ..links.base import LinkError
from ..protocol.timing import BIT_TIME, CHAR_TIME
from ..sim.bus import Frame
from ..transcript import TOOL, Event, EventKind, escape

#: a frame's start meaning "as soon as the line is free" (the bus starts a frame at the later
#: of its start and the end of what is on the line)
LINE_FREE = float("-inf")


#: how every divergence's message starts (a report's stop reason names it)
DIVERGED = "replay diverged"


class ReplayDiverged(LinkError):
    """The tool's stimuli no longer follow the recording."""


class RecordingEnded(ReplayDiverged):
    """The recording stops before the run it records did (a capture cut short): what it
    holds is judged, the rest is left open (an incomplete run, exit 2, not a tool failure)."""


class RecordedSensor:
    """A :class:`~conformance.sim.bus.BusDevice` that answers from a recording."""

    name = "recording"

    def __init__(self, events: list[Event]) -> None:
        wire = sorted(
            (e for e in events if e.kind is not EventKind.NOTE), key=lambda e: (e.start, e.end)
        )
        self.tool = [e for e in wire if e.origin == TOOL]
        self.replies = [e for e in wire if e.origin != TOOL and e.kind is EventKind.CHAR]
        # how many tool events the recording has before each reply character starts
        self._needs: list[int] = []
        i = 0
        for reply in self.replies:
            while i < len(self.tool) and self.tool[i].start < reply.start:
                i += 1
            self._needs.append(i)
        self.heard = 0  # tool events matched so far
        self.next_reply = 0
        self.offset = 0.0  # now minus recorded time, at the last matched tool event
        # the frame next_frame offered, by (next_reply, heard): what it depends on moves only
        # with those two (offset with heard), and the bus asks again at every step between
        self._offered: tuple[int, int, Frame | None] = (-1, -1, None)

    # -- what the tool does -------------------------------------------------------------------
    def on_break(self, start: float, end: float) -> None:
        self._match(EventKind.BREAK, 0, end, end - start)

    def on_char(self, wire: int, start: float, end: float) -> None:
        self._match(EventKind.CHAR, wire, end)

    def _match(self, kind: EventKind, wire: int, end: float, length: float = 0.0) -> None:
        if self.heard >= len(self.tool):
            raise RecordingEnded(
                f"the recording ends at {end:.3f} s, before its run did (cut short?): the "
                f"tool sent {_describe(kind, wire)} there and nothing more was recorded"
            )
        expected = self.tool[self.heard]
        if not same_action(expected, kind, wire, length):
            raise ReplayDiverged(
                f"{DIVERGED} at {end:.3f} s (recorded {expected.start:.3f} s): the tool "
                f"sent {_describe(kind, wire)}, the recording has "
                f"{_describe(expected.kind, expected.wire)}"
            )
        self.heard += 1
        self.offset = end - expected.end

    # -- what the recording says the sensor did -------------------------------------------------
    def next_frame(self) -> Frame | None:
        at, heard, frame = self._offered
        if at == self.next_reply and heard == self.heard:
            return frame
        frame = self._next_frame()
        self._offered = (self.next_reply, self.heard, frame)
        return frame

    def _next_frame(self) -> Frame | None:
        if self.next_reply >= len(self.replies):
            return None
        if self._needs[self.next_reply] > self.heard:
            return None  # its question has not been asked yet
        reply = self.replies[self.next_reply]
        start = reply.start + self.offset
        before = self._just_before(reply)
        if before is not None and abs(reply.start - before.end) <= (
            reply.uncertainty + before.uncertainty
        ):
            # back to back with what was on the line before it, within what the recording can
            # tell (a capture's edges sit on its sample grid): it goes the moment the line is
            # free, so it wins the line against the tool's next frame, as recorded (else the
            # order of frames that touch could turn on a few microseconds of quantization)
            start = LINE_FREE
        return Frame(start, reply.wire, reply.end - reply.start)

    def _just_before(self, reply: Event) -> Event | None:
        """The recorded event that ended last before ``reply``: the tool's last matched one
        or the previous reply character."""
        found = [self.tool[self.heard - 1]] if self.heard else []
        if self.next_reply:
            found.append(self.replies[self.next_reply - 1])
        found = [e for e in found if e.start < reply.start]
        return max(found, key=lambda e: e.end, default=None)

    def pop_frame(self) -> Frame:
        frame = self.next_frame()
        assert frame is not None, "the bus pops only a frame that was offered"
        self.next_reply += 1
        return frame


def same_action(recorded: Event, kind: EventKind, wire: int, length: float) -> bool:
    """Whether the tool's break or character is the recorded one. A spacing shorter than a
    frame (a probe below the break threshold) is, on a captured wire, indistinguishable from
    a character whose low bits are the spacing: a capture decoder reports it as one."""
    if kind is EventKind.CHAR:
        return recorded.kind is EventKind.CHAR and recorded.wire == wire
    if recorded.kind is EventKind.BREAK:
        return True
    if length >= CHAR_TIME:
        return False
    low = recorded.wire & 0xFF
    spacing_bits = 1 + ((low & -low).bit_length() - 1 if low else 8)  # start bit + zeros
    return abs(spacing_bits - length / BIT_TIME) <= 1.0


def _describe(kind: EventKind, wire: int) -> str:
    if kind is EventKind.BREAK:
        return "a break"
    return f"'{escape(chr(wire & 0x7F))}'"
