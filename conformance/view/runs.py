"""Runs of sensor characters, cut for timing evidence rather than for meaning.

A :class:`~.segments.Transmission` frames its reply as the protocol does (to the LF, ETX or
packet length): what a recorder must take as the answer. The whole-run timing and framing
rules ask something else: every character a sensor sent, grouped so each character gap is
measured inside one talker's run. A :class:`Segment` regroups a transmission's characters
that way: the reply is the run that starts within 87 ms of the command and goes on while
characters follow within :data:`RUN_GAP` (a late next line of multi-line text within
:data:`LINE_RUN_GAP`); everything later is ``later`` (service requests, chatter), and what
overlapped the command is ``contention``. Both cuts come from the one segmentation.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from ..protocol.commands import Kind
from ..protocol.timing import NO_BREAK_WINDOW
from ..transcript import Event
from .segments import IsRecorder, Transmission, read_view
from .sides import LF, STX

REPLY_SEARCH = NO_BREAK_WINDOW  # a sensor run starting later than this is not a reply
RUN_GAP = 0.05  # characters closer than this belong to one run (lenient, for evidence)
LINE_RUN_GAP = 1.0  # a late next line of multi-line text still belongs to its reply


@dataclass
class Segment:
    """A command (with the break before it, if any) and the sensor runs after it."""

    break_event: Event | None
    command: list[Event]
    reply: list[Event] = field(default_factory=list)
    later: list[Event] = field(default_factory=list)
    contention: list[Event] = field(default_factory=list)  # a sensor talked over the command
    text: str = ""
    binary_reply: bool = False  # replies to aDBn! are 8N1 packets (no 7E1, no CR LF)

    @property
    def command_end(self) -> float:
        return self.command[-1].end

    @property
    def multiline(self) -> bool:
        """A reply starting ``a<STX>`` is multi-line text (decision A10)."""
        return len(self.reply) > 1 and self.reply[1].char7 == STX

    @classmethod
    def of(cls, t: Transmission) -> Segment:
        cmd = t.command if t.is_command else None
        seg = cls(
            t.break_event,
            list(t.chars),
            text=t.text,
            binary_reply=cmd is not None and cmd.kind is Kind.BINARY_DATA,
        )
        for e in t.heard:
            if not t.is_command or e.start < t.end:
                seg.contention.append(e)  # not a reply: it overlapped the command
            else:
                _place(seg, e)
        return seg


def _place(seg: Segment, e: Event) -> None:
    if seg.later:
        seg.later.append(e)
        return
    if not seg.reply:
        (seg.reply if e.start - seg.command_end <= REPLY_SEARCH else seg.later).append(e)
        return
    last = seg.reply[-1]
    ended = not seg.binary_reply and last.char7 == LF and not seg.multiline
    # the next line of multi-line text may come late (R-4.4.13.1-03 judges how late)
    allowed = LINE_RUN_GAP if seg.multiline and last.char7 == LF else RUN_GAP
    if ended or e.start - last.end > allowed:
        seg.later.append(e)
    else:
        seg.reply.append(e)


def segments(events: Iterable[Event], is_recorder: IsRecorder | None = None) -> list[Segment]:
    """The recording's transmissions, regrouped for timing evidence."""
    return [Segment.of(t) for t in read_view(events, is_recorder).transmissions]


def runs(events: list[Event]) -> list[list[Event]]:
    """Split sensor characters into runs separated by more than :data:`RUN_GAP` of marking."""
    out: list[list[Event]] = []
    for e in events:
        if out and e.start - out[-1][-1].end <= RUN_GAP:
            out[-1].append(e)
        else:
            out.append([e])
    return out
