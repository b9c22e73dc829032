"""Runs of sensor characters, cut for timing evidence rather than for meaning.

A :class:`~.segments.Transmission` frames its reply as the protocol does (to the LF, ETX or
packet length): what a recorder must take as the answer. The whole-run timing and framing
rules regroup a transmission's characters so each is judged where it belongs: a
:class:`Segment`'s reply is the run that starts within 87 ms of the command and goes on to
its protocol end (the LF; ETX or a late line of multi-line text beyond :data:`LINE_RUN_GAP`;
a binary packet's length), whatever gaps lie inside it: a gap is evidence for the
character-gap rule only, and a gap on stamps the link saw irregular may not be there at all
(issue 18: a reply cut at its stamps' gaps became three "replies" with framing FAILs).
Everything later is ``later`` (service requests, chatter), and what overlapped the command,
or came back between the echoes of its characters (:data:`~conformance.transcript.COLLISION`),
is ``contention``: never the DUT's reply text. Both cuts come from the one segmentation.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import TypeVar, overload

from ..protocol.binary import packet_length
from ..protocol.commands import Kind
from ..protocol.framing import ETX, LF, STX
from ..protocol.timing import NO_BREAK_WINDOW
from ..transcript import SEVEN_BITS, Event, Transcript, decode_8n1, wire_bytes
from .segments import IsRecorder, TranscriptView, Transmission, memo, read_view

#: a module constant (:meth:`Segment.of`): a member read off the enum goes through its metaclass's
#: ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_BINARY_DATA = Kind.BINARY_DATA

T = TypeVar("T")

#: How a gap's stamps are worth where it lies: ``(start, end) -> uncertainty`` (s).
GapUncertainty = Callable[[float, float], float]

REPLY_SEARCH = NO_BREAK_WINDOW  # a sensor run starting later than this is not a reply
RUN_GAP = 0.05  # unsolicited characters closer than this belong to one run (evidence only)
LINE_RUN_GAP = 1.0  # a late next line of multi-line text still belongs to its reply
_LF_BYTE = bytes([LF])


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
    #: the sensor's breaks after the command (:attr:`Transmission.sensor_breaks`)
    sensor_breaks: tuple[Event, ...] = ()
    #: the recorder's break that met the reply still coming (:attr:`Transmission.met_by`)
    met_by: Event | None = None

    @property
    def command_end(self) -> float:
        return self.command[-1].end

    @property
    def multiline(self) -> bool:
        """A reply starting ``a<STX>`` is multi-line text (decision A10)."""
        return len(self.reply) > 1 and self.reply[1].char7 == STX

    @property
    def reply_ended(self) -> bool:
        """The reply reached its protocol end: LF (single line), ETX (multi-line text), the
        packet's length (``aDBn!``)."""
        if not self.reply:
            return False
        if self.binary_reply:
            # the size field is in the first three bytes: decoding the whole packet for each
            # byte placed made a long packet quadratic
            length = packet_length(decode_8n1(self.reply[:3]))
            return length is not None and len(self.reply) >= length
        last = self.reply[-1].char7
        return last == ETX if self.multiline else last == LF

    @classmethod
    def of(cls, t: Transmission) -> Segment:
        is_command = t.is_command  # (asked once: it reads the text's stem each time)
        cmd = t.command if is_command else None
        seg = cls(
            t.break_event,
            list(t.chars),
            text=t.text,
            binary_reply=cmd is not None and cmd.kind is _BINARY_DATA,
            sensor_breaks=t.sensor_breaks,
            met_by=t.met_by,
        )
        heard = t.heard
        if not is_command:  # asked once, not per character heard
            seg.contention.extend(heard)  # not a reply: it met the command
            return seg
        contention = t.contention
        if not contention:  # nearly always: no set of none made
            _place_all(seg, heard)
            return seg
        clash = {id(e) for e in contention}
        for e in heard:
            if id(e) in clash:
                seg.contention.append(e)  # not a reply: it met the command (or its tail did)
            else:
                _place(seg, e)
        return seg


def _place_all(seg: Segment, heard: list[Event]) -> None:
    """:func:`_place` of each of ``heard`` in turn, a one-line 7E1 reply's characters in one
    slice: once its first two characters are placed (no STX second: no multi-line text),
    every character up to its LF is the reply's and everything after is ``later``, which is
    what placing them one by one comes to (a run's sensor characters number 10^4 to 10^5)."""
    n = len(heard)
    i = 0
    while i < n and not seg.later and len(seg.reply) < 2:
        _place(seg, heard[i])
        i += 1
    if i == n:
        return
    reply = seg.reply
    if seg.later or seg.binary_reply or reply[1].wire & 0x7F == STX:
        for e in heard[i:]:
            _place(seg, e)
        return
    if reply[-1].wire & 0x7F == LF:  # ended: the rest is later
        seg.later.extend(heard[i:])
        return
    j = _first_lf(heard, i)
    reply.extend(heard[i : j + 1])  # up to and with its LF (all of it when none came)
    seg.later.extend(heard[j + 1 :])


def _first_lf(heard: list[Event], i: int) -> int:
    """The index of the first LF (7 bits) among ``heard[i:]``, or ``len(heard)`` when none
    came: found in one C pass over their wire bytes where each wire is a byte."""
    wires = wire_bytes(heard[i:])
    if wires is not None:
        k = wires.translate(SEVEN_BITS).find(_LF_BYTE)
        return len(heard) if k < 0 else i + k
    n = len(heard)
    while i < n and heard[i].wire & 0x7F != LF:
        i += 1
    return i


def _place(seg: Segment, e: Event) -> None:
    """``e`` into the reply or ``later``. Asked for every character a run's sensor sent
    (once more per whole-run cut), so :attr:`Segment.multiline` and
    :attr:`Segment.reply_ended` are spelled out here for a 7E1 reply."""
    if seg.later:
        seg.later.append(e)
        return
    reply = seg.reply
    if not reply:
        (reply if e.start - seg.command_end <= REPLY_SEARCH else seg.later).append(e)
        return
    last = reply[-1]
    last7 = last.wire & 0x7F
    multiline = len(reply) > 1 and reply[1].wire & 0x7F == STX
    # the next line of multi-line text may come late (R-4.4.13.1-03 judges how late)
    late_line = multiline and last7 == LF and e.start - last.end > LINE_RUN_GAP
    ended = seg.reply_ended if seg.binary_reply else last7 == (ETX if multiline else LF)
    if ended or late_line:
        seg.later.append(e)
    else:
        reply.append(e)  # a gap never ends a reply: R-7.0-12 judges it


class Segments(list[Segment]):
    """The segments of one recording (a list), holding what judges derive from them: a run's
    whole-run cases read the same segments several times (a rule's judge and the probe that
    asks what it wants confirmed), and derive the gaps and their observations once."""

    def derived(self, name: str, key: object, build: Callable[[], T]) -> T:
        """``build()``, kept under ``name`` while ``key`` (and the list's length) stays the
        same."""
        return memo(self, name, (len(self), key), build)


def segments(events: Iterable[Event], is_recorder: IsRecorder | None = None) -> Segments:
    """The recording's transmissions, regrouped for timing evidence."""
    return Segments(Segment.of(t) for t in read_view(events, is_recorder).transmissions)


def transcript_view(transcript: Transcript) -> TranscriptView:
    """:func:`~.segments.read_view` of a run's whole transcript, cut once per length (a
    transcript is append-only). A passive judgement's records, the whole-run cases' segments
    and the report's evidence all read this one cut: an hour's capture cut again for each
    took seconds (the direction inference and the segmentation over 10^5 events). A live
    run's transcript that a session cuts as it grows (:mod:`.live_cut`) gives that cut's
    view, the same, without cutting every event again."""
    events = transcript.events
    live = transcript.__dict__.get("_live_cut")

    def cut() -> TranscriptView:
        if live is not None and live.advance(events):
            return live.view()
        return read_view(events)

    return memo(transcript, "_view", len(events), cut)


def transcript_segments(transcript: Transcript) -> Segments:
    """:func:`segments` of a run's whole transcript, cut once per length (a transcript is
    append-only): the whole-run cases and the report's timing diagrams read the same cut."""
    return memo(
        transcript,
        "_segments",
        len(transcript.events),
        lambda: Segments(Segment.of(t) for t in transcript_view(transcript).transmissions),
    )


class LazyCut(Sequence[Segment]):
    """A whole transcript's segments (:func:`transcript_segments`' list, item for item) made
    from its view's transmissions as they are read, none held: each read of an item makes it
    again (:meth:`Segment.of` of one transmission, which depends on that transmission alone).
    A passive judgement's reports search the whole run's exchanges for a finding's evidence
    (:mod:`~conformance.reports.evidence`) and a whole-run case's worst value
    (:func:`~conformance.reports.timing_diagram.exchange_behind`); holding the whole list
    for them kept 11.5 MB at an hour of a busy bus (770 bytes a segment) through every run
    (issue 22). :meth:`texts` gives the segments' texts without making them."""

    def __init__(self, transmissions: Sequence[Transmission]) -> None:
        self.transmissions = transmissions

    def __len__(self) -> int:
        return len(self.transmissions)

    @overload
    def __getitem__(self, i: int) -> Segment: ...
    @overload
    def __getitem__(self, i: slice) -> list[Segment]: ...
    def __getitem__(self, i: int | slice) -> Segment | list[Segment]:
        if isinstance(i, slice):
            return [Segment.of(t) for t in self.transmissions[i]]
        return Segment.of(self.transmissions[i])

    def __iter__(self) -> Iterator[Segment]:
        return map(Segment.of, self.transmissions)

    def texts(self) -> list[str]:
        """Every segment's text, in order (kept: one reference a segment, the strings are
        the transmissions' own)."""
        return memo(
            self, "_texts", len(self.transmissions), lambda: [t.text for t in self.transmissions]
        )


def whole_cut(transcript: Transcript) -> Segments | LazyCut:
    """The whole transcript's segments for a report's search: the held list where a whole-run
    case of this run cut it already (:func:`transcript_segments`), else a :class:`LazyCut`
    of the same segments that holds none (a passive judgement's sensor runs each cut their
    own sensor's only)."""
    held = transcript.__dict__.get("_segments")
    if held is not None and held[0] == len(transcript.events):
        return held[1]
    windowed = transcript.__dict__.get("_whole_transmissions")
    if windowed is not None and windowed[0] == len(transcript.events):
        # a loaded recording's windows (its bus pass): the whole view's transmissions read
        # window by window, no whole view cut (issue 22)
        return LazyCut(windowed[1]())
    return LazyCut(transcript_view(transcript).transmissions)


def runs(events: list[Event], gap: float = RUN_GAP) -> list[list[Event]]:
    """Split characters into runs separated by more than ``gap`` of marking (sensor runs by
    default; the tool's transmissions with a shorter gap, :mod:`~..tool_recorder.contention`)."""
    out: list[list[Event]] = []
    for e in events:
        if out and e.start - out[-1][-1].end <= gap:
            out[-1].append(e)
        else:
            out.append([e])
    return out


def frames(events: list[Event], uncertainty: GapUncertainty | None = None) -> list[list[Event]]:
    """Split unsolicited sensor characters (service requests, chatter) as a recorder frames
    them: after each LF, and at a gap surely longer than :data:`RUN_GAP` given the stamps'
    ``uncertainty`` there (one the link's irregular stamps may have made is no gap)."""
    out: list[list[Event]] = []
    for e in events:
        if out:
            prev = out[-1][-1]
            gap = e.start - prev.end
            u = uncertainty(prev.start, e.end) if uncertainty is not None else 0.0
            if prev.char7 != LF and gap - u <= RUN_GAP:
                out[-1].append(e)
                continue
        out.append([e])
    return out
