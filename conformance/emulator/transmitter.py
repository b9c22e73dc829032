"""The emulator's output side: replies scheduled at a start time, offered frame by frame.

The bus asks for the next frame and commits it when its time comes; until then plans can
change (a break cancels a pending service request), which is why output is a queue of
scheduled transmissions rather than something pushed onto the wire.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

from ..protocol.timing import CHAR_TIME
from ..sim.bus import BreakFrame, Frame
from .replies import Reply, ReplyKind


@dataclass
class Transmission:
    """One reply's frames, the start of the first one and the marking between them."""

    reply: Reply
    start: float
    wires: list[int]
    gap: float
    sent: int = 0
    char_time: float = CHAR_TIME  # one frame; differs only for a sensor at the wrong baud rate
    #: (index, s) each: extra marking before the frame at that index (a fault's pause in a
    #: reply); several faults' pauses in one reply each hold the frames from theirs on (an
    #: aI! reply with ident-pause's 4 ms inside and stray-after-line-end's 2 ms after its LF)
    pauses: tuple[tuple[int, float], ...] = ()
    #: A break of the sensor's own before the first frame (s of spacing, 0.0: none), then
    #: ``marking`` (s) before that frame: the line is the transmission's from
    #: :attr:`begin`. Offered as a :class:`~conformance.sim.bus.BreakFrame` ahead of the
    #: characters (the sim bus puts it in the transcript as the sensor's BREAK).
    spacing: float = 0.0
    marking: float = 0.0
    spaced: bool = False  # the break has gone out

    @property
    def lead(self) -> float:
        """The line time taken before the first frame: the break and the marking after it."""
        return self.spacing + self.marking if self.spacing else 0.0

    @property
    def begin(self) -> float:
        """Where the transmission takes the line: its break's start, else its first frame's."""
        return self.start - self.lead if self.spacing else self.start

    def spacing_frame(self) -> BreakFrame:
        """The break before the first frame, as the bus takes it."""
        end = self.start - self.marking
        return BreakFrame(end - self.spacing, 0, self.spacing, end)

    def held(self, index: int) -> float:
        """The marking the pauses add before the frame at ``index``: 0.0 with none, else
        their sum (each pause's own value where it is the only one: the same floats as one)."""
        if not self.pauses:
            return 0.0
        return sum(extra for at, extra in self.pauses if 0 < at <= index)

    def frame_start(self, index: int) -> float:
        start = self.start + index * (self.char_time + self.gap)
        # + held(index): 0.0 with no pauses, added as the constant rather than called per
        # frame (the same float: x + 0.0, a -0.0 made 0.0 as before)
        return start + self.held(index) if self.pauses else start + 0.0

    def frame(self, index: int) -> Frame:
        return Frame(self.frame_start(index), self.wires[index], self.char_time)

    @property
    def end(self) -> float:
        """End of the last stop bit."""
        return self.frame_start(len(self.wires) - 1) + self.char_time

    @property
    def done(self) -> bool:
        return self.sent >= len(self.wires)

    def rest(self) -> Iterator[tuple[float, int, float]]:
        """``(start, wire, duration)`` of the frames not sent yet, in order: :meth:`frame`
        of each index from :attr:`sent` on (the same arithmetic, so the same floats)."""
        step = self.char_time + self.gap
        start, wires, char_time, held = self.start, self.wires, self.char_time, self.held
        if not self.pauses:  # held(index) is 0.0 for each: added, not called (frame_start)
            for index in range(self.sent, len(wires)):
                yield start + index * step + 0.0, wires[index], char_time
            return
        for index in range(self.sent, len(wires)):
            yield start + index * step + held(index), wires[index], char_time


class Transmitter:
    """Scheduled transmissions; never two at once (a later one waits for the earlier)."""

    def __init__(self) -> None:
        self.queue: list[Transmission] = []
        # the frame next_frame last offered, with the transmission and index it is of: the
        # bus asks for it again and again while it waits (about 1.5 times a frame sent)
        self._offered: tuple[Transmission, int, Frame] | None = None

    def schedule(
        self,
        reply: Reply,
        start: float,
        gap: float,
        char_time: float = CHAR_TIME,
        *,
        pauses: tuple[tuple[int, float], ...] = (),
        spacing: float = 0.0,
        marking: float = 0.0,
    ) -> Transmission:
        """``reply`` to go out at ``start`` (its first frame), or after the transmissions
        already on the line then; ``spacing``: a break of the sensor's before it, ending
        ``marking`` before its first frame (:attr:`Transmission.spacing`)."""
        wires = reply.wires()
        queue = self.queue
        if queue:  # (rare: nearly always nothing is planned, nothing to wait for)
            lead = spacing + marking if spacing else 0.0
            for other in queue:
                if other.begin <= start - lead < other.end + CHAR_TIME:
                    start = other.end + CHAR_TIME + lead
        item = Transmission(
            reply,
            start,
            wires,
            gap,
            char_time=char_time,
            pauses=pauses,
            spacing=spacing,
            marking=marking,
        )
        if not queue:
            # nothing to move out of its way, and a queue of one is in order (what
            # _make_way and the sort below come to then)
            queue.append(item)
            return item
        self._make_way(item)
        self.queue.append(item)
        self.queue.sort(key=lambda t: t.start)
        return item

    def _make_way(self, item: Transmission) -> None:
        """Move transmissions planned to start while ``item`` is on the wire (a service
        request due in the middle of a reply scheduled after it) to after it, whole, as a
        later one waits for an earlier: the bus would otherwise send their frames that fell
        due meanwhile back to back (at the wire's ``max(start, now)``), dropping the
        marking the sensor puts between its characters (an ``inter-char-gap`` sensor's 3 ms)."""
        end = item.end
        for other in sorted(self.queue, key=lambda t: t.start):
            if (
                other is not item
                and other.sent == 0
                and not other.spaced
                and item.begin <= other.begin < end + CHAR_TIME
            ):
                other.start = end + CHAR_TIME + other.lead
                end = other.end
                self._offered = None  # its frames are not where they were offered

    def line_taken_until(self, end: float) -> None:
        """Another talker's character held the one wire until ``end``: the bus sends this
        device's next frame, if planned before then, at ``end``. A sensor that puts marking
        between its characters (a gap or a pause) keeps it after that frame, so the rest of
        the transmission moves with it, and what waits for it moves after it (as
        :meth:`_make_way`). Without this the frames that fell due meanwhile went out back to
        back at the bus's ``max(start, now)``, an ``inter-char-gap`` sensor's reply that met a
        retry showing 8.33 ms spacings it never sends (truth19). A reply without marking
        goes out back to back either way: it is left as planned (the same frames)."""
        if not self.queue:
            return
        item = self.queue[0]
        if not item.gap and not item.pauses:
            return
        late = end - item.frame_start(item.sent)
        if late > 0:
            item.start += late
            self._offered = None  # its frames are not where they were offered
            self._make_way(item)

    def cancel(self, keep: Callable[[Transmission], bool] | None = None) -> None:
        """Drop pending output (all of it, or what ``keep`` rejects)."""
        self.queue = [t for t in self.queue if keep is not None and keep(t)]

    def cancel_kind(self, kind: ReplyKind) -> None:
        self.cancel(lambda t: t.reply.kind is not kind or t.sent > 0)

    def next_frame(self) -> Frame | None:
        if not self.queue:
            return None
        item = self.queue[0]
        offered = self._offered
        if offered is not None and offered[0] is item and offered[1] == item.sent:
            return offered[2]  # a transmission is never changed once scheduled
        if item.spacing and not item.spaced:
            return item.spacing_frame()  # its break first (not kept: offered until taken)
        frame = item.frame(item.sent)
        self._offered = (item, item.sent, frame)
        return frame

    def ahead(self) -> Iterator[tuple[float, int, float]] | None:
        """The frames :meth:`next_frame` would offer one after the other while nothing
        changes the queue: the rest of its first transmission (``sim.bus.PlansFrames``).
        None when there is none, when its frames' ends might not rise (a gap or pause
        shorter than nothing), which :meth:`pop_frames` relies on, or while its break is
        still to go (a frame of another kind)."""
        if not self.queue:
            return None
        item = self.queue[0]
        if item.char_time + item.gap <= 0 or any(extra < 0 for _, extra in item.pauses):
            return None
        if item.spacing and not item.spaced:
            return None  # its break goes first, frame by frame (the bus's BreakFrame)
        return item.rest()

    def pop_frames(self, count: int) -> tuple[float, Transmission]:
        """Commit the first ``count`` (at least one) frames :meth:`ahead` offered, as
        ``count`` calls of :meth:`pop_frame`; returns the last one's end (the latest: ends
        rise within a transmission) and the transmission they are of."""
        item = self.queue[0]
        item.sent += count
        last = item.frame_start(item.sent - 1) + item.char_time
        if item.done:
            self.queue.pop(0)
        return last, item

    def pop_frame(self) -> tuple[Frame, Transmission]:
        item = self.queue[0]
        frame = self.next_frame()
        assert frame is not None
        if type(frame) is BreakFrame:
            item.spaced = True  # its characters follow
            return frame, item
        item.sent += 1
        if item.done:
            self.queue.pop(0)
        return frame, item
