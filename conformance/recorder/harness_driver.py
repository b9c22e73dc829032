"""A recorder harness as the recorder under test (``--role recorder --port exec:...``).

Per scenario the harness is started afresh (``unix:`` connects afresh), told the job through
the protocol (``job TASK COMMAND...``) and the ``SDI12_*`` environment ``--trigger`` also sets,
and then driven on the tool's own :class:`~conformance.sim.bus.SimLink`, exactly where the
in-process golden recorder acts: each ``tx``/``brk`` it plans is put on the virtual-time bus
unless a played sensor's character comes first, in which case the harness hears that first and
plans again. Its side of the wire has origin ``tool``, so the recorder judges read it as they
read the golden recorder's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..harness import protocol as proto
from ..harness.channel import Channel, HarnessError
from ..harness.device import open_channel
from ..harness.protocol import Plan, PlanKind, Role
from ..links.base import Link
from ..links.errors import PortUnavailable
from ..recorder_jobs import RecorderOutput, Request
from ..sim.bus import SimBus, earliest_frame
from ..transcript import HELD_BACK, Event
from .job_time import JobBudget, JobTimeout

#: Bus time one job may take when the session states no budget (:mod:`..recorder.job_time`).
JOB_LIMIT = 600.0
#: Bus time a harness may stay ``idle`` with nothing on the line before its job counts as over.
IDLE_END = 10.0


def _first(events: list[Event]) -> bool:
    return True


def _stderr_of(channel: Channel) -> str | None:
    """The tail of what the harness wrote to stderr (None for a socket harness)."""
    tail = getattr(channel, "stderr_tail", None)
    return tail() if callable(tail) else None


@dataclass
class HarnessRecorder:
    """Drives the harness at ``port`` (``exec:...`` or ``unix:...``) once per scenario."""

    port: str
    reply_timeout: float | None = None
    kind: str = "harness"
    needs_real_time: bool = False
    version: int = 1  # the protocol version the harness answered hello with (probe)

    def act(
        self, scenario: str, request: Request, link: Link, budget: JobBudget | None = None
    ) -> RecorderOutput:
        budget = budget or JobBudget(JOB_LIMIT, "the harness's default")
        env = request.environment(scenario, budget.seconds)
        channel = open_channel(self.port, env, self.reply_timeout)
        cut: JobTimeout | None = None
        try:
            name = channel.greet(Role.RECORDER)
            first = proto.job(link.now(), str(request.task), request.commands)
            plan = channel.plan(first, Role.RECORDER, link.now())
            ended, cannot = self._drive(channel, plan, link, budget)
            channel.finish(proto.BYE)
        except JobTimeout as exc:
            cut = exc
        finally:
            channel.close(proto.BYE)
        stderr = _stderr_of(channel)  # read once it has exited: nothing more can come
        if cut is not None:  # judged on what it sent: its own log goes with it
            cut.stderr = stderr
            raise cut
        out = RecorderOutput(cannot=cannot, stderr=stderr)
        out.notes.append(f"harness {name or self.port}: {ended}")
        for log in channel.logs:  # several lines for one command append, in order
            out.logged.setdefault(log.command, []).extend(log.values)
        if channel.logs:
            out.log_source = f"{len(channel.logs)} log line(s) from the harness"
        return out

    def probe(self) -> None:
        """Start the harness and exchange hellos once, so a wrong command is a usage error
        before the run (a :class:`~conformance.ports.PortError`), not an ERROR in it."""
        try:
            channel = open_channel(self.port, None, self.reply_timeout)
            try:
                channel.greet(Role.RECORDER)
                self.version = channel.version
            finally:
                channel.close(proto.BYE)
        except HarnessError as exc:
            raise PortUnavailable(str(exc)) from exc

    def _drive(
        self, channel: Channel, plan: Plan, link: Link, budget: JobBudget
    ) -> tuple[str, str | None]:
        """Carry out plans until ``done`` or ``cannot``; what ended the job, in words, and
        the ``cannot`` reason (None: the harness did not say it cannot). A harness still
        busy when the budget runs out is cut there (:class:`JobTimeout`)."""
        limit = link.now() + budget.seconds
        held = False  # its break was held back for a sensor's character (:func:`_holds_back`)
        while plan.kind not in (PlanKind.DONE, PlanKind.CANNOT):
            if plan.kind is PlanKind.IDLE:
                deadline = link.now() + IDLE_END
            else:
                deadline = proto.seconds(plan.start)
            if deadline > limit and plan.kind is not PlanKind.IDLE:
                # what it plans lies past the cut: listen until then
                heard = link.receive(limit, until=_first)
                if not heard:
                    raise JobTimeout(budget.seconds, budget.reason)
                got = heard[0]
                message = _quiet(channel, link, limit, proto.heard(got.wire, got.start, got.end))
                plan = channel.plan(message, Role.RECORDER, got.end, got.start)
                continue
            heard = link.receive(deadline, until=_first)
            if heard:
                got = heard[0]
                held = plan.kind is PlanKind.BRK and (held or _holds_back(plan, got))
                message = _quiet(channel, link, limit, proto.heard(got.wire, got.start, got.end))
                plan = channel.plan(message, Role.RECORDER, got.end, got.start)
                continue
            if plan.kind is PlanKind.IDLE:
                return f"idle with a quiet line for {IDLE_END:g} s of bus time", None
            if plan.kind is PlanKind.WAIT:
                message = proto.time_is(link.now())
            elif plan.kind is PlanKind.TX:
                done = _transmit(link, plan)
                message = proto.sent(done.wire, done.start, done.end)
            else:  # BRK
                made = link.send_break(proto.seconds(plan.end) - link.now())
                if held or _moved(plan, made):
                    _mark_held_back(link, made)
                message = proto.line_break(made.start, made.end)
            held = False
            now = made.end if plan.kind is PlanKind.BRK else link.now()  # see _quiet
            message = _quiet(channel, link, limit, message, now)
            plan = channel.plan(message, Role.RECORDER, now)
        if plan.kind is PlanKind.CANNOT:
            return "cannot" + (f" {plan.reason}" if plan.reason else ""), plan.reason
        return "done", None


def _holds_back(plan: Plan, got: Event) -> bool:
    """Whether the played sensor's character ``got``, heard before the break ``plan`` went
    out, was on the line at the break's start: the line gave it the line, and the break the
    harness plans next is this one held back, not a new decision. On a wire the recorder's
    break goes over the character (it drives the line regardless), so the end the line gives
    it is not the one the recorder's own timing had (docs/kit.md, twenty-second round)."""
    return got.end > proto.seconds(plan.start)


def _moved(plan: Plan, made: Event) -> bool:
    """Whether the line began the break ``made`` later than ``plan`` asked (past the slack a
    plan for "now" has, :data:`~..harness.protocol.PAST_SLACK_US`): a played sensor's
    character planned for the same instant took the line first and the break followed it
    whole (:meth:`~..sim.bus.SimBus.tool_break`; the twenty-second round's library began its
    break for ``0IM!`` where the sensor's 51st character of ``0XHELP!`` text began)."""
    return made.start > proto.seconds(plan.start + proto.PAST_SLACK_US)


def _mark_held_back(link: Link, made: Event) -> None:
    """``made``, the break the line held back, marked :data:`~..transcript.HELD_BACK` in the
    transcript where it stands (the devices that talked on under it come after it)."""
    events = link.transcript.events
    for i in range(len(events) - 1, -1, -1):
        if events[i] is made:
            events[i] = replace(made, text=HELD_BACK)
            return


def _quiet(
    channel: Channel, link: Link, limit: float, message: str, now: float | None = None
) -> str:
    """``message`` with its QUIET field for a ``batch`` harness on the sim bus: nothing
    starts on the line before the played sensors' next character (each knows it: they are
    sans-I/O) or the job's cut at ``limit``, unless the harness transmits first; so it wakes
    itself for its waits until then (a logger sketch polling for a service request).

    ``now``: the message's time (default: the link's clock). A break is told at its END
    (docs/harness-protocol.md), though the link's clock may be later: a played sensor that
    was talking went on under it (the sim bus commits its character whole), and that
    character, not yet told, comes next as a ``char``; no promise reaches past its start.
    (The twenty-fourth round's ATtiny logger restarted at a reply's first edge and broke
    again while the sensor talked: its answer, a wait from the break's end, was checked
    against the end of that untold character, "not after now", an ERROR that stopped the
    run.)"""
    bus = getattr(link, "bus", None)
    if proto.BATCH not in channel.features or not isinstance(bus, SimBus):
        return message
    nxt = earliest_frame(bus.devices)
    quiet = limit if nxt is None else min(limit, nxt[1].start)
    if bus.rx:
        quiet = min(quiet, bus.rx[0].start)
    return proto.with_quiet(message, quiet, link.now() if now is None else now)


def _transmit(link: Link, plan: Plan) -> Event:
    """The planned character on the line: a version-2 harness's frame lasts what it says
    (its firmware's own bit time, so the recorder's bit rate is judged), else one frame."""
    bus = getattr(link, "bus", None)  # the job's link stands in front of the sim bus's
    if plan.duration and bus is not None:
        return bus.tool_char(plan.wire, link.now(), proto.seconds(plan.duration))
    return link.write(bytes([plan.wire]))[0]
