"""A sensor harness on the virtual-time sim bus (``--port exec:...`` / ``unix:...``, role
sensor): the device under test lives in another process and is told, message by message, what
happens on the line; its plan (next character, or a wake-up time) is what the bus asks for.

The tool owns the clock, so stamps are exact (uncertainty 0) and a run is deterministic:
whatever the harness does with wall time (a slow build, a loaded CI machine) cannot show up on
the wire.
"""

from __future__ import annotations

from ..links.base import LinkInfo
from ..links.errors import PortUnavailable
from ..links.registry import LinkKind, OpenedPort, PortOptions, register
from ..protocol.timing import CHAR_TIME
from ..results import CaseRecord
from ..sim.bus import BreakFrame, Frame, SimBus, SimLink, VirtualClock
from ..transcript import TOOL, Event, EventKind
from ..verdicts import Verdict
from . import protocol as proto
from .channel import Channel, ChildChannel, HarnessError, SocketChannel
from .protocol import Plan, PlanKind, Role


class HarnessDevice:
    """:class:`~conformance.sim.bus.BusDevice` whose state machine runs in the harness."""

    def __init__(self, channel: Channel, clock: VirtualClock, name: str = "harness") -> None:
        self.name = name
        self.channel = channel
        self.clock = clock
        self._plan = Plan(PlanKind.IDLE)
        self._start = 0.0  # the plan's time in s
        self._pending: float | None = None  # time of a message whose answer is unread
        self._since: float | None = None  # START of the frame that message reported
        self.harness_name = channel.greet(Role.SENSOR)
        #: the harness takes ``chars`` batches and a QUIET field (``hello V+batch``)
        self.batches = proto.BATCH in channel.features
        self._unsent: str | None = None  # a batch harness's message, told when needed
        #: bus time (s) before which the tool starts nothing but what this device's own
        #: characters lead to: set by :class:`HarnessBus` before it asks for a plan, void
        #: once anything happens on the line (:meth:`_tell`)
        self.quiet: float | None = None

    def _tell(self, message: str, now: float, since: float | None = None) -> None:
        """Tell a line event; its answer is read when the plan is next needed, so the bus
        does its bookkeeping while the harness works (half the wall time on 2 cores). A
        batch harness is told then too, with the QUIET field known at that moment (how long
        the line stays the device's: it wakes itself for its waits until then)."""
        self._collect()
        self.quiet = None
        if self.batches:
            self._unsent = message
        else:
            self.channel.send(message)
        self._pending, self._since = now, since

    def _collect(self) -> None:
        if self._pending is not None:
            now, self._pending = self._pending, None
            if self._unsent is not None:
                message, self._unsent = self._unsent, None
                self.channel.send(proto.with_quiet(message, self.quiet, now))
            self._plan = plan = self.channel.read_plan(Role.SENSOR, now, self._since)
            # the harness saw ``now`` rounded to the microsecond; when it answers with that
            # very time it means this instant, not half a microsecond before or after it
            exact = plan.start == proto.us(now)
            self._start = now if exact else proto.seconds(plan.start)

    @property
    def plan(self) -> Plan:
        self._collect()
        return self._plan

    @property
    def wake_at(self) -> float | None:
        return self._start if self.plan.kind is PlanKind.WAIT else None

    def wake(self, now: float) -> None:
        self._tell(proto.time_is(now), now)

    def hear_chars(self, frames: list[tuple[int, float, float]]) -> int:
        """Tell a batch harness the tool's characters ``(wire, start, end)`` of one write
        in one ``chars`` message; how many it heard (it stops where its plan would act
        before the next character starts: the rest is then the bus's to send as usual)."""
        self._collect()
        self.channel.send(proto.heard_chars(frames))
        in_us = [(wire, proto.us(start), proto.us(end)) for wire, start, end in frames]
        taken, plan = self.channel.read_heard(Role.SENSOR, in_us)
        now = frames[taken - 1][2]
        self._plan = plan
        self._start = now if plan.start == proto.us(now) else proto.seconds(plan.start)
        return taken

    def on_break(self, start: float, end: float) -> None:
        self._tell(proto.line_break(start, end), end, start)

    def on_char(self, wire: int, start: float, end: float) -> None:
        self._tell(proto.heard(wire, start, end), end, start)

    def next_frame(self) -> Frame | None:
        plan = self.plan
        if plan.kind is PlanKind.BRK:  # a sensor's break: the line held spacing
            end = proto.seconds(plan.end)
            return BreakFrame(self._start, 0, end - self._start, end)
        if plan.kind is not PlanKind.TX:
            return None
        # a version-2 harness (a firmware kit) names the frame's own length: its bit time
        duration = proto.seconds(plan.duration) if plan.duration else CHAR_TIME
        return Frame(self._start, plan.wire, duration)

    def pop_frame(self) -> Frame:
        frame = self.next_frame()
        if frame is None:
            raise HarnessError("the bus committed a character the harness did not plan")
        if isinstance(frame, BreakFrame):  # told back as a recorder's own break is
            start, end = frame.placed(self.clock.now)
            self._tell(proto.line_break(start, end), end)
            return frame
        start = max(frame.start, self.clock.now)  # as SimBus._commit places it
        end = start + frame.duration
        self._tell(proto.sent(frame.wire, start, end), end)
        return frame


class HarnessBus(SimBus):
    """The sim bus, plus wake-ups: a harness that answered ``wait T`` is told ``time T`` when
    the clock gets there with nothing else on the line first.

    Never inside the tool's own break: a break is told when it ends, and a ``time T`` for a
    T after its start would tell the harness that nothing happened until T (a sensor's
    service request due then went out over the break; a kit's sketch ran on past its start
    and heard it late)."""

    _held_from: float | None = None  # the start of the tool's break being held

    def _watch_clash(self, at: float, end: float) -> None:
        """The tool takes the line from ``at`` to ``end``: if the harness wants it then too
        (a character planned for ``at`` or before, which the tool's own goes ahead of), both
        would talk at once on a wire. A kit's sketch that began a frame inside the tool's
        character is planned so, once per character, until the line is free (the kit says
        so on stderr): it then reads as a reply begun 0 ms after the command, cut short where
        the firmware heard the clash (Open-SDI12-Blue's "a0000" after an abort break,
        docs/kit.md). :attr:`SimBus.clashed` marks it; the view takes it for contention."""
        nxt = self._next()
        if nxt is not None and nxt[1].start <= at:
            self.clashed = end

    def tool_break(self, duration: float, at: float | None = None) -> Event:
        self.advance(self.clock.now if at is None else at)
        start = self.clock.now if at is None else at
        self._watch_clash(start, start + duration)
        self._held_from = start
        try:
            return super().tool_break(duration, at)
        finally:
            self._held_from = None

    def tool_char(self, wire: int, start: float, duration: float = CHAR_TIME) -> Event:
        self.advance(start)
        self._watch_clash(self.clock.now, self.clock.now + duration)
        return super().tool_char(wire, start, duration)

    def _promise(self, limit: float) -> None:
        """Before a plan is asked for: the tool starts nothing before ``limit`` (inside its
        own break, nothing after the break's start), which a batch harness alone on the bus
        is told with its next message (its QUIET field). Alone: another device's characters
        would be line events it has not been told of."""
        if len(self.devices) == 1 and isinstance(device := self.devices[0], HarnessDevice):
            device.quiet = self._held_from if self._held_from is not None else limit

    def _wake_before(self, limit: float) -> bool:
        """Wake the earliest harness due before ``limit`` (and before the next character)."""
        self._promise(limit)
        due = [(d.wake_at, d) for d in self.devices if getattr(d, "wake_at", None) is not None]
        if not due:
            return False
        when, device = min(due, key=lambda pair: pair[0])
        if self._held_from is not None and when > self._held_from:
            return False  # the break message answers it
        nxt = self._next()
        if when >= limit or (nxt is not None and nxt[1].start < when):
            return False
        self.clock.advance_to(when)
        device.wake(self.clock.now)
        return True

    def advance(self, time: float) -> None:
        while True:
            if self._wake_before(time):
                continue
            self._promise(time)  # still so after a character of the device's own
            nxt = self._next()
            if nxt is None or nxt[1].start >= time:
                break
            self._commit(*nxt)
        self.clock.advance_to(time)

    def step(self, limit: float):  # noqa: ANN201 - as SimBus.step
        while self._wake_before(limit):
            pass
        self._promise(limit)  # until its next character: the tool may answer that
        return super().step(limit)

    def tool_chars(self, wire: bytes, start: float, gap: float) -> list[Event]:
        """The tool's characters from ``start``, ``gap`` apart, told to the one batch
        harness in one message: the events of those it heard, placed exactly as
        :meth:`~conformance.sim.bus.SimBus.tool_char` places them one by one (nothing of the
        device's comes between: it would have stopped the batch). At least one."""
        self.advance(start)
        time, frames = self.clock.now, []
        for byte in wire:
            frames.append((byte, time, time + CHAR_TIME))
            time = time + CHAR_TIME + gap
        self._watch_clash(frames[0][1], frames[0][2])
        taken = self.devices[0].hear_chars(frames)  # type: ignore[attr-defined]
        events = []
        for byte, first, end in frames[:taken]:
            events.append(self.transcript.add(Event(EventKind.CHAR, TOOL, first, end, wire=byte)))
            self.clock.advance_to(end)
        return events


class HarnessLink(SimLink):
    """The tool's end of a :class:`HarnessBus`; closing it ends the harness."""

    runs_harness = True

    def __init__(self, bus: HarnessBus, device: HarnessDevice, kind: str) -> None:
        super().__init__(bus)
        self.device = device
        # a version-2 harness gives each frame's own duration: the bit rate is observed
        timed = device.channel.version >= 2
        self.info = LinkInfo(kind=kind, virtual_time=True, bit_timing=timed, frame_lengths=timed)

    def check_records(self, cases: list[CaseRecord]) -> None:
        """Before the verdicts: end the harness and make sure its answers were in step
        (:meth:`Channel.finish`; raises :class:`HarnessError` if not). A harness that failed
        at any point may have been out of step for a while before it showed (a line written
        unasked shifts every answer after it), so no FAIL recorded through it is trusted: each
        becomes INCONCLUSIVE, saying why. A harness fault is never a verdict about the DUT."""
        channel = self.device.channel
        try:
            if not channel.closed:
                self.device.plan  # noqa: B018 - reads an answer still due
                channel.finish(proto.BYE)
        finally:
            if channel.failure is not None:
                distrust_fails(cases, channel.failure)

    def harness_stderr(self) -> str | None:
        """The tail of what the harness wrote to stderr (None for a socket harness, which
        has none): kept in every report, since a harness's own log explains a verdict as
        often as it explains a failure."""
        tail = getattr(self.device.channel, "stderr_tail", None)
        return tail() if callable(tail) else None

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        """As :meth:`SimLink.write`; to a batch harness alone on the bus, up to
        ``BATCH_MAX`` characters a message (one round trip for a command, not one a
        character), the same events at the same times."""
        bus = self.bus
        if not (self.device.batches and isinstance(bus, HarnessBus) and len(bus.devices) == 1):
            return super().write(wire, gap)
        events: list[Event] = []
        time = self.now()
        while len(events) < len(wire):
            rest = wire[len(events) : len(events) + proto.BATCH_MAX]
            if len(rest) == 1:
                events.append(bus.tool_char(rest[0], time))
            else:
                events.extend(bus.tool_chars(rest, time, gap))
            time = events[-1].end + gap
        return events

    def close(self) -> None:
        self.device.channel.close(proto.BYE)


def distrust_fails(cases: list[CaseRecord], failure: str) -> None:
    """Turn every FAIL of ``cases`` into INCONCLUSIVE: the harness failed (``failure``)."""
    for case in cases:
        changed = False
        for finding in case.findings:
            if finding.verdict is Verdict.FAIL:
                finding.verdict = Verdict.INCONCLUSIVE
                finding.detail = f"not trusted, the harness failed in this run: {finding.detail}"
                changed = True
        if changed:
            case.summarise()


def is_harness_port(port: str) -> bool:
    return port.startswith(("exec:", "unix:"))


def open_channel(
    port: str, env: dict[str, str] | None = None, reply_timeout: float | None = None
) -> Channel:
    """``exec:PROGRAM ARGS`` starts the program; ``unix:PATH`` connects to a socket."""
    kind, _, rest = port.partition(":")
    timeout = {} if reply_timeout is None else {"reply_timeout": reply_timeout}
    if kind == "exec":
        return ChildChannel(rest.strip(), env, **timeout)
    return SocketChannel(rest, **timeout)


def open_sensor_harness(port: str, reply_timeout: float | None = None) -> HarnessLink:
    """The harness named by ``port`` as the one sensor on a virtual-time bus."""
    channel = open_channel(port, reply_timeout=reply_timeout)
    bus = HarnessBus()
    try:
        device = HarnessDevice(channel, bus.clock)
    except HarnessError:
        channel.close()
        raise
    bus.attach(device)
    return HarnessLink(bus, device, port.partition(":")[0])


def _open_kind(port: str, options: PortOptions) -> OpenedPort:
    """A sensor harness: virtual time, so the bench options (echo, direction) do not apply."""
    try:
        return OpenedPort(open_sensor_harness(port))
    except HarnessError as exc:
        raise PortUnavailable(str(exc)) from exc


KINDS = tuple(
    register(
        LinkKind(
            name,
            matches=lambda port, name=name: port.startswith(f"{name}:"),
            open_sensor_role=_open_kind,
            info=LinkInfo(kind=name, virtual_time=True, bit_timing=False),
            example=example,
        )
    )
    for name, example in (("exec", "exec:python3 my_harness.py"), ("unix", "unix:/tmp/dut.sock"))
)
