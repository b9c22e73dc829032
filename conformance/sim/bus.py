"""An in-process SDI-12 bus on a virtual clock.

The clock moves only when the tool waits, writes or breaks, and then jumps straight to the
next thing that happens, so a measurement announcing ttt=999 takes milliseconds of wall time.
Each character takes exactly one 10-bit frame (8.33 ms); breaks last what was asked; every
event is stamped exactly (uncertainty 0).

Devices on the bus are sans-I/O: they hear breaks and characters as stamped events and offer
the characters they want to send, each with its start time (:class:`BusDevice`). A device's
plans may change when it hears something (a break cancels a pending service request), so the
bus only ever asks for the *next* character and commits it once its time has come.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from ..links.base import LineEnd, Link, LinkInfo, StopCondition
from ..protocol.timing import CHAR_TIME
from ..transcript import (
    COLLISION,
    DUT,
    TOOL,
    Event,
    EventKind,
    Transcript,
    full_event,
    wire_event,
)


@dataclass(frozen=True, slots=True)
class Frame:
    """A character a device wants on the wire: its start time and its 8 wire bits."""

    start: float
    wire: int
    duration: float = CHAR_TIME  # one 10-bit frame; a device at the wrong baud rate differs


#: The text a sensor's break carries in the transcript (an event of kind BREAK whose origin is
#: the sensor's; the tool's own breaks are origin ``tool``).
SENSOR_BREAK = "the sensor held the line spacing (a break)"


@dataclass(frozen=True)
class BreakFrame(Frame):
    """A device's break: the line held spacing from ``start`` to ``end`` (s), offered as a
    frame (a sensor harness's ``brk``: firmware that "wakes" the line before its reply; a
    recording of one, replayed). ``duration`` is its planned length: a break the line could
    only begin later (the tool's character was still on it) keeps its planned END, as a
    recorder's held-back break does, or, planned to end before the line was free, its whole
    length from there."""

    end: float = 0.0

    def placed(self, now: float) -> tuple[float, float]:
        """Its start and end on the line, the clock at ``now`` when it is committed."""
        start = max(self.start, now)
        return start, self.end if self.end > start else start + self.duration


class BusDevice(Protocol):
    """A simulated device (sensor emulator, or a simulated recorder)."""

    name: str

    def on_break(self, start: float, end: float) -> None: ...

    def on_char(self, wire: int, start: float, end: float) -> None: ...

    def next_frame(self) -> Frame | None:
        """The next character this device will send, if nothing else happens first."""

    def pop_frame(self) -> Frame:
        """Commit the character :meth:`next_frame` offered; it is now on the wire."""


@runtime_checkable
class PlansFrames(Protocol):
    """A device that can tell its next characters ahead, so the bus commits a reply in one
    tight loop instead of asking :meth:`BusDevice.next_frame` for each (issue 22: a run's
    10^4 to 10^5 device characters each cost a dozen calls that way)."""

    def frames_ahead(self) -> Iterator[tuple[float, int, float]] | None:
        """``(start, wire, duration)`` of the characters :meth:`BusDevice.next_frame` would
        offer one after the other, each after the one before was committed, as long as the
        device hears nothing (the rest of one planned transmission: a later one may start
        elsewhere). None where it cannot tell; then the bus asks frame by frame. Worked out
        from the device's own plan alone: the bus keeps its clock aside while it draws them
        (:meth:`SimLink._kept_run`)."""

    def pop_frames(self, count: int) -> None:
        """Commit the first ``count`` of :meth:`frames_ahead`: what ``count`` calls of
        :meth:`BusDevice.pop_frame` do."""


def earliest_frame(devices: list[BusDevice]) -> tuple[BusDevice, Frame] | None:
    """The device whose next character starts first, and that character (None if silent)."""
    if len(devices) == 1:  # one sensor: the usual bus, asked once or twice per character
        frame = devices[0].next_frame()
        return None if frame is None else (devices[0], frame)
    best: tuple[BusDevice, Frame] | None = None
    for device in devices:
        frame = device.next_frame()
        if frame is not None and (best is None or frame.start < best[1].start):
            best = (device, frame)
    return best


class VirtualClock:
    def __init__(self, start: float = 0.0) -> None:
        self.now = start

    def advance_to(self, time: float) -> None:
        if time > self.now:
            self.now = time


class SimBus:
    """The wire: devices plus the tool's link, sharing one virtual clock and transcript."""

    def __init__(self, devices: list[BusDevice] | None = None) -> None:
        self.clock = VirtualClock()
        self.devices: list[BusDevice] = list(devices or [])
        self.transcript = Transcript()
        self.rx: deque[Event] = deque()  # device characters the tool has not read yet
        # a bus whose subclass changes how characters are committed (a harness's wake-ups)
        # asks frame by frame: only this class's own step is what planned_run repeats
        self._runs = type(self).step is SimBus.step and type(self).advance is SimBus.advance
        # likewise the tool's characters: only this class's own tool_char, advance and
        # _next are what tool_run spells out
        kind = type(self)
        self._plain_writes = (
            self._runs and kind.tool_char is SimBus.tool_char and kind._next is SimBus._next
        )
        self._checked: tuple[BusDevice | None, bool] = (None, False)
        #: set by a bus that watches for it (:class:`~conformance.harness.device.HarnessBus`):
        #: the end of the tool's transmission that went first over a device frame planned
        #: for the same instant or earlier; the device's next character planned by then is
        #: marked :data:`~conformance.transcript.COLLISION`. The in-process emulators' bus
        #: leaves it None: their timing faults are judged as they always were.
        self.clashed: float | None = None

    def planned_run(self) -> tuple[PlansFrames, Iterator[tuple[float, int, float]]] | None:
        """The one device on the bus and its :meth:`PlansFrames.frames_ahead`, where the bus
        may commit those in a run (:meth:`SimLink.receive`); None: ask frame by frame."""
        devices = self.devices
        if not self._runs or len(devices) != 1:
            return None
        device = devices[0]
        checked, plans = self._checked
        if checked is not device:
            plans = isinstance(device, PlansFrames)
            self._checked = (device, plans)
        if not plans:
            return None
        frames = device.frames_ahead()  # type: ignore[attr-defined]
        return None if frames is None else (device, frames)  # type: ignore[return-value]

    def attach(self, device: BusDevice) -> None:
        self.devices.append(device)

    def _next(self) -> tuple[BusDevice, Frame] | None:
        return earliest_frame(self.devices)

    def advance(self, time: float) -> None:
        """Let devices transmit everything that starts before ``time``, then set the clock."""
        while (nxt := self._next()) is not None and nxt[1].start < time:
            self._commit(*nxt)
        self.clock.advance_to(time)

    def step(self, limit: float) -> Event | None:
        """Commit the next device character if it starts before ``limit``."""
        nxt = self._next()
        if nxt is None or nxt[1].start >= limit:
            return None
        return self._commit(*nxt)

    def _commit(self, device: BusDevice, frame: Frame) -> Event:
        if type(frame) is BreakFrame:
            return self._commit_break(device, frame)
        device.pop_frame()
        start = max(frame.start, self.clock.now)
        end = start + frame.duration
        origin = DUT if len(self.devices) == 1 else device.name
        if self.clashed is not None and frame.start <= self.clashed:
            # it wanted the line while the tool's own transmission took it: two talkers
            self.clashed = None
            event = full_event(EventKind.CHAR, origin, start, end, frame.wire, COLLISION, 0.0, None)
            event = self.transcript.add(event)
        else:
            event = self.transcript.add(wire_event(EventKind.CHAR, origin, start, end, frame.wire))
        for other in self.devices:
            if other is not device:
                other.on_char(frame.wire, start, end)
        self.clock.advance_to(end)
        self.rx.append(event)
        return event

    def _commit_break(self, device: BusDevice, frame: BreakFrame) -> Event:
        """A device's break (:class:`BreakFrame`) in the transcript as a BREAK of its origin,
        the line spacing from its start to its end: what the sensor did, for the judges to
        see (a UART-based recorder would read it as a NUL with a framing error, then nothing
        until the line marks again); the other devices hear it as a break."""
        start, end = frame.placed(self.clock.now)
        device.pop_frame()
        if self.clashed is not None and frame.start <= self.clashed:
            self.clashed = None  # the break was what wanted the line under the tool's own
        origin = DUT if len(self.devices) == 1 else device.name
        event = self.transcript.add(Event(EventKind.BREAK, origin, start, end, text=SENSOR_BREAK))
        for other in self.devices:
            if other is not device:
                other.on_break(start, end)
        self.clock.advance_to(end)
        return event

    # tool-side actions
    def tool_break(self, duration: float, at: float | None = None) -> Event:
        """The tool's break of ``duration`` from now, or from ``at`` (a recorded break played
        again where it was sent): a device's character begun before ``at`` is committed whole
        and moves the clock past ``at``, but the break still began at ``at``, over it, as a
        recorder's break over a reply still coming does (R-7.0-06's marking is counted from
        its end)."""
        self.advance(self.clock.now if at is None else at)
        start = self.clock.now if at is None else at
        end = start + duration
        event = self.transcript.add(Event(EventKind.BREAK, TOOL, start, end))
        self.advance(end)  # devices that were talking keep talking (contention is theirs)
        for device in self.devices:
            device.on_break(start, end)
        return event

    def tool_char(self, wire: int, start: float, duration: float = CHAR_TIME) -> Event:
        """The tool's character on the line (``duration``: one frame; other than 8.33 ms only
        for a faulty recorder at the wrong bit rate)."""
        self.advance(start)
        start = self.clock.now
        end = start + duration
        event = self.transcript.add(wire_event(EventKind.CHAR, TOOL, start, end, wire))
        for device in self.devices:
            device.on_char(wire, start, end)
        self.clock.advance_to(end)
        return event

    def tool_run(self, wires: bytes, start: float, gap: float) -> list[Event]:
        """:meth:`tool_char` of each of ``wires`` in turn, the first at ``start``, each next
        one ``gap`` after the end of the event the transcript kept for the one before: what
        :meth:`SimLink.write` did character by character, the same events, stamps, clock and
        devices' hearing, spelt out in one loop (issue 22: a command's 5 to 12 characters
        each went through three calls and an event maker; a fault-matrix row writes some
        6,000). Only for a bus whose own tool_char, advance and _next are this class's."""
        devices, clock = self.devices, self.clock
        if len(devices) == 1:  # the usual bus: one sensor, asked and told directly
            return self._tool_run_to_one(wires, start, gap)
        add = self.transcript.add
        char = EventKind.CHAR
        events: list[Event] = []
        time = start
        for wire in wires:
            # advance(time): the devices' characters that start before it, then the clock
            while (nxt := earliest_frame(devices)) is not None and nxt[1].start < time:
                self._commit(*nxt)
            now = clock.now
            if time > now:
                clock.now = now = time
            end = now + CHAR_TIME
            event = add(full_event(char, TOOL, now, end, wire, "", 0.0, None))
            for device in devices:
                device.on_char(wire, now, end)
            if end > clock.now:
                clock.now = end
            events.append(event)
            time = event.end + gap
        return events

    def _tool_run_to_one(self, wires: bytes, start: float, gap: float) -> list[Event]:
        """:meth:`tool_run` on a bus of one device: the same events, stamps, clock and
        hearing, with the device's :meth:`~BusDevice.next_frame` and
        :meth:`~BusDevice.on_char` taken once for the run rather than found through
        :func:`earliest_frame` and the device list per character, and each event made in
        place as :func:`~conformance.transcript.full_event` makes it (a fault-matrix row
        writes some 8,000 characters a half, issue 22)."""
        device = self.devices[0]
        next_frame, hear, commit = device.next_frame, device.on_char, self._commit
        clock = self.clock
        transcript = self.transcript
        add = transcript.add
        # the transcript's own add keeps the event as it is: appended here, not called
        keep = (
            transcript.events.append
            if type(transcript).add is Transcript.add and "add" not in vars(transcript)
            else None
        )
        char = EventKind.CHAR
        events: list[Event] = []
        time = start
        for wire in wires:
            # advance(time): the device's characters that start before it, then the clock
            while (frame := next_frame()) is not None and frame.start < time:
                commit(device, frame)
            now = clock.now
            if time > now:
                clock.now = now = time
            end = now + CHAR_TIME
            made = full_event(char, TOOL, now, end, wire, "", 0.0, None)
            if keep is not None:
                keep(made)
                event = made
            else:
                event = add(made)
            hear(wire, now, end)
            if end > clock.now:
                clock.now = end
            events.append(event)
            time = event.end + gap
        return events


#: a module constant: a member read off the enum goes through its metaclass's ``__getattr__``
#: hook on Python 3.11 (issue 22, matrix25)
_CHAR = EventKind.CHAR


class SimLink(Link):
    """The tool's end of a :class:`SimBus`."""

    reads_line_at_once = True  # receive's idle counts from a LineEnd's before (Link)

    def __init__(self, bus: SimBus) -> None:
        self.bus = bus
        self.transcript = bus.transcript
        self.info = LinkInfo(kind="sim", virtual_time=True)

    def now(self) -> float:
        return self.bus.clock.now

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        return self.bus.tool_break(duration)  # a virtual clock is exact either way

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        bus = self.bus
        if bus._plain_writes:
            return bus.tool_run(wire, bus.clock.now, gap)
        events = []
        time = self.now()
        for byte in wire:
            event = self.bus.tool_char(byte, time)
            events.append(event)
            time = event.end + gap
        return events

    def wait_until(self, time: float) -> None:
        self.bus.advance(time)

    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        got: list[Event] = []
        bus = self.bus
        rx = bus.rx  # the bus's one queue (cleared in place, never replaced): per character
        # the line's characters before this read: the idle counts from the last of them
        # until one of the read's own has come (reads_line_at_once)
        before = until.before if idle is not None and type(until) is LineEnd else None
        while True:
            if rx:
                got.append(rx.popleft())
                if until is not None and until(got):
                    return got
                continue
            limit = deadline
            if idle is not None:
                last = got[-1] if got else before[-1] if before else None
                if last is not None:
                    limit = min(limit, last.end + idle)
            run = bus.planned_run()
            if run is not None:
                ended, limit = self._take_run(run, got, limit, deadline, until, idle)
                if ended is None:
                    continue  # that transmission is all on the wire: the next one's turn
                if ended:
                    return got
            elif bus.step(limit) is not None:
                continue
            bus.clock.advance_to(max(limit, bus.clock.now))
            return got

    def receive_line(
        self,
        deadline: float,
        rest_deadline: Callable[[Event], float],
        most: int,
        idle: float,
    ) -> list[Event] | None:
        """A one-line reply's two reads in one pass over the lone device's planned run:
        ``receive(deadline, until=<any character>)`` for its first character, then, where
        that is not the reply already, ``receive(rest_deadline(first), until=LineEnd([first],
        most), idle=idle)`` for the rest (the tool recorder's read of a one-line 7E1 reply,
        ``ToolRecorder._listen``), with the same events, stamps, clock and device's state
        (issue 22, matrix18: a second read, its planned run and its device's offer per reply,
        some 2,000 a fault-matrix row). Returns the characters of both reads together (none:
        no character began before ``deadline``), or None, having done nothing, where the
        reads cannot go so (characters already queued, a bus that commits frame by frame,
        a transcript that keeps events its own way, a receive of the link's own): the
        caller then reads as usual."""
        bus = self.bus
        if bus.rx or type(self).receive is not SimLink.receive or "receive" in vars(self):
            return None  # (a receive of its own, a wrapped one included, reads as it will)
        transcript = bus.transcript
        if type(transcript).add is not Transcript.add or "add" in vars(transcript):
            return None
        run = bus.planned_run()
        if run is None:
            return None
        device, frames = run
        clock = bus.clock
        # the first read: _kept_run stopping at any character, the limit the deadline,
        # spelt out for its one character (a call and a loop's set-up per reply)
        offered = next(frames, None)
        if offered is None:
            return None  # no frame offered after all: nothing done, read as usual
        start, wire, duration = offered
        if start >= deadline:
            clock.advance_to(max(deadline, clock.now))  # the run stopped at its limit
            return []
        now = clock.now
        if start < now:  # max(start, now), spelt out
            start = now
        end = start + duration
        first = full_event(_CHAR, DUT, start, end, wire, "", 0.0, None)
        transcript.events.append(first)
        if end > now:
            clock.now = now = end
        got = [first]
        if most <= 1:  # the reply is at its limit already: no second read
            clock.now = now
            device.pop_frames(1)
            return got
        # the second read: its limit from the first character (receive's idle rule), then
        # on through the same planned run, as _kept_run goes with a LineEnd of [first]
        rest = rest_deadline(first)
        waited = None  # where the read's limit stopped it (the clock goes there)
        try:
            waited, ended = self._rest_of_run(frames, got, rest, most, idle, now)
        finally:
            device.pop_frames(len(got))
            if waited is not None:  # receive's end at its limit: the line marked till then
                clock.advance_to(max(waited, clock.now))
        if ended:
            return got
        # that transmission is all on the wire: the second read goes on as receive does
        return got + self.receive(rest, until=LineEnd(got, most), idle=idle)

    def _rest_of_run(
        self,
        frames: Iterator[tuple[float, int, float]],
        got: list[Event],
        rest: float,
        most: int,
        idle: float,
        now: float,
    ) -> tuple[float | None, bool]:
        """:meth:`receive_line`'s second read over the planned run ``frames``, after the
        first character ``got[0]``, the clock at ``now``: :meth:`_kept_run` with
        ``LineEnd([first], most)`` (its ``got`` holding the first already), the limit
        ``rest`` and ``idle``. Returns the limit that stopped it (None: none did) and
        whether the read is over (False: the run ran out)."""
        self.bus.clock.now = now
        limit = min(rest, got[0].end + idle)
        stop, limit = self._line_run(frames, got, limit, rest, most, idle)
        if stop is None:
            return None, False  # the run is all sent
        return (None if stop else limit), True

    def _line_run(
        self,
        frames: Iterator[tuple[float, int, float]],
        got: list[Event],
        limit: float,
        deadline: float,
        most: int,
        idle: float,
    ) -> tuple[bool | None, float]:
        """:meth:`_kept_run` with ``LineEnd([], most)``, no ``until`` and ``idle`` given (the
        second read of :meth:`receive_line`, after ``got``'s first character), spelt out: no
        branch per character for the stops it does not have, and the characters kept into
        the transcript in one ``extend`` when the loop ends (nothing reads the transcript
        while it runs: no stop condition is called), which is the same list the append per
        character left (issue 22: some 18,000 reply characters a fault-matrix row's half)."""
        clock = self.bus.clock
        char = _CHAR
        already = len(got)
        last7 = got[-1].wire & 0x7F if got else -1
        now = clock.now
        try:
            for start, wire, duration in frames:
                if start >= limit:
                    return False, limit
                if start < now:  # max(start, now), spelt out
                    start = now
                end = start + duration
                made = full_event(char, DUT, start, end, wire, "", 0.0, None)
                if end > now:
                    now = end
                got.append(made)
                wire7 = wire & 0x7F
                if len(got) >= most or (last7 == 0x0D and wire7 == 0x0A):
                    return True, limit
                last7 = wire7
                later = end + idle
                limit = later if later < deadline else deadline  # min(deadline, later)
            return None, limit
        finally:
            clock.now = now
            self.bus.transcript.events.extend(got[already:])

    def _take_run(
        self,
        run: tuple[PlansFrames, Iterator[tuple[float, int, float]]],
        got: list[Event],
        limit: float,
        deadline: float,
        until: StopCondition | None,
        idle: float | None,
    ) -> tuple[bool | None, float]:
        """Commit the lone device's planned characters into ``got`` exactly as the loop of
        :meth:`receive` over :meth:`SimBus.step` would, one by one (the same events, stamps,
        clock and limits), but without asking the device for each. Returns True: ``until``
        said stop; False: the next character starts at or past the limit; None: the run is
        all sent; and the limit of the read as the last character left it."""
        device, frames = run
        clock = self.bus.clock
        transcript = self.bus.transcript
        add = transcript.add  # (what it returns is the event: a test may restamp it)
        # the transcript's own add keeps the event as it is: appended here, not called
        keep = (
            transcript.events.append
            if type(transcript).add is Transcript.add and "add" not in vars(transcript)
            else None
        )
        char = EventKind.CHAR
        # full_event called in place (not wire_event): a run's 10^4..10^5 characters each
        # went through a call more
        # a one-line reply's stop (LineEnd) checked here, not called after each character:
        # the characters before this read's and the 7 bits of the last one so far
        line = until if type(until) is LineEnd else None
        if line is not None:
            until = None
            held = len(line.before)
            last = got[-1] if got else line.before[-1] if line.before else None
            last7 = -1 if last is None else last.wire & 0x7F
        already = len(got)
        try:
            if keep is not None:
                return self._kept_run(frames, got, limit, deadline, until, idle, line, keep)
            for start, wire, duration in frames:
                if start >= limit:
                    return False, limit
                now = clock.now
                if start < now:  # max(start, now), spelt out
                    start = now
                end = start + duration
                made = full_event(char, DUT, start, end, wire, "", 0.0, None)
                event = add(made)
                if end > now:
                    clock.now = end
                got.append(event)
                if line is not None:
                    wire7 = event.wire & 0x7F
                    if held + len(got) >= line.most or (last7 == 0x0D and wire7 == 0x0A):
                        return True, limit
                    last7 = wire7
                elif until is not None and until(got):
                    return True, limit
                if idle is not None:
                    later = event.end + idle
                    limit = later if later < deadline else deadline  # min(deadline, later)
            return None, limit
        finally:
            if len(got) > already:
                device.pop_frames(len(got) - already)

    def _kept_run(
        self,
        frames: Iterator[tuple[float, int, float]],
        got: list[Event],
        limit: float,
        deadline: float,
        until: StopCondition | None,
        idle: float | None,
        line: LineEnd | None,
        keep: Callable[[Event], None],
    ) -> tuple[bool | None, float]:
        """:meth:`_take_run`'s loop where the transcript's own add keeps each event as it
        is (``keep``: its list's append), so the event made is the event kept: its wire and
        end are read from the locals they were set from, and the clock is kept in a local
        while the loop runs, written back before anything outside it may read it (``until``)
        and when the loop ends. Nothing else runs meanwhile (the device's plan is
        arithmetic on its transmission), so the clock, events and limits are the same."""
        clock = self.bus.clock
        char = EventKind.CHAR
        room = last7 = 0
        if line is not None:
            # LineEnd inline: ``before`` and ``got`` reach ``most``, or the last two are CR LF
            room = line.most - len(line.before)
            last = got[-1] if got else line.before[-1] if line.before else None
            last7 = -1 if last is None else last.wire & 0x7F
        now = clock.now
        try:
            for start, wire, duration in frames:
                if start >= limit:
                    return False, limit
                if start < now:  # max(start, now), spelt out
                    start = now
                end = start + duration
                made = full_event(char, DUT, start, end, wire, "", 0.0, None)
                keep(made)
                if end > now:
                    now = end
                got.append(made)
                if line is not None:
                    wire7 = wire & 0x7F
                    if len(got) >= room or (last7 == 0x0D and wire7 == 0x0A):
                        return True, limit
                    last7 = wire7
                elif until is not None:
                    clock.now = now
                    stop = until(got)
                    now = clock.now
                    if stop:
                        return True, limit
                if idle is not None:
                    later = end + idle
                    limit = later if later < deadline else deadline  # min(deadline, later)
            return None, limit
        finally:
            clock.now = now
