"""Faulty golden recorders: the recorder role's fault-detection matrix (design.md 5).

Each fault is the golden recorder with one deviation (a policy value, engine hooks
(:class:`~conformance.tool_recorder.hooks.Hooks`), a small ToolRecorder subclass overriding a
public method, or a recorder knob) and the requirements it breaks. The matrix test runs the whole
recorder suite against each and demands that exactly those requirements come out FAIL/WARN.
Where one deviation honestly breaks several rules (a recorder that never retries also never
retries on a bad CRC), all of them are declared, with the reason in the description.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from ..links.base import Link
from ..protocol.commands import Command, Kind, parse_command
from ..protocol.responses import service_request
from ..recorder_jobs import RecorderOutput, Request, Task
from ..sim.bus import SimBus
from ..tool_recorder import Measurement, Policy, ToolRecorder
from ..tool_recorder.engine import _service_request_end
from ..tool_recorder.hooks import Engine, Hooks
from ..tool_recorder.records import OK, Attempt, Exchange
from ..tool_recorder.validity import ends_line
from ..transcript import Event, decode_7e1
from .compose import Parts, compose, conflict
from .golden import GoldenHooks, GoldenRecorder, GoldenToolRecorder, logged_values

EARLY_RETRY = 12e-3  # s after the command: inside the 16.67 ms that R-7.2-02 forbids
LATE_RETRY = 95e-3  # s after the command: past the 87 ms of R-7.2-02
LATE_D0 = 95e-3  # s after the service request: past the 87 ms of R-7.1-01
FAST_CHAR_TIME = 8.0e-3  # s per frame: 1250 baud, 4% fast (A14 allows 2%)
POLL_TIMEOUT = 1.5  # s a logger library waited for a reply before it tried again (issue 20)
#: s after the command a reply must have started by for ``short-reply-timeout``: the
#: reference sensor's 9 ms fit, the 15.40 ms a sensor may take (R-7.0-10) do not
SHORT_REPLY_TIMEOUT = 10e-3


class SilentRetryHooks(GoldenHooks):
    """The golden hooks with the first retry after silence in each sequence timed by
    :meth:`silent_retry_time`, every other retry passed on (``CHAINS``). A fault that times
    only that retry (too early, too late) overrides :meth:`silent_retry_time` alone, so it
    composes with one that times the retries after a reply (talks-over-reply's engine time),
    and two that time that retry apart are refused: both override :meth:`silent_retry_time`."""

    CHAINS = frozenset({"retry_time"})

    def retry_time(
        self,
        master: Engine,
        exchange: Exchange,
        sequence: int,
        per_sequence: int,
        usual: Callable[[], float],
    ) -> float:
        """:meth:`silent_retry_time` for the sequence's first retry after no reply; the next
        hooks' time otherwise."""
        prev = exchange.last
        first_retry = not any(a.sequence == sequence and a.retry for a in exchange.attempts)
        if first_retry and not prev.reply_events and prev.command_end is not None:
            return max(self.silent_retry_time(master, prev), master.link.now())
        return super().retry_time(master, exchange, sequence, per_sequence, usual)

    def silent_retry_time(self, master: Engine, prev: Attempt) -> float:
        """When the retry after ``prev`` (an attempt that drew no reply) starts."""
        raise NotImplementedError(f"{type(self).__name__} times no retry after silence")


class EarlyRetryHooks(SilentRetryHooks):
    """Retries a silent sensor 12 ms after the command (the first retry of each sequence)."""

    def silent_retry_time(self, master: Engine, prev: Attempt) -> float:
        """12 ms after the command."""
        assert prev.command_end is not None
        return prev.command_end + EARLY_RETRY


class SkipsNextBreakHooks(GoldenHooks):
    """The golden hooks, able to leave out the break the break rules put in front of the next
    command: a deviation decided before the command it applies to goes out. Otherwise it
    passes the decision on (``CHAINS``): with no-break-after-87ms, whose rules break only for
    a new address, a skipped break is skipped and the rest follow those rules."""

    CHAINS = frozenset({"needs_break"})

    skip_break = False

    def needs_break(
        self, master: Engine, address: str, at: float, usual: Callable[[], bool]
    ) -> bool:
        """No break once after ``skip_break`` was set; the next hooks' rules otherwise."""
        if self.skip_break:
            self.skip_break = False
            return False
        return super().needs_break(master, address, at, usual)


class LateRetryHooks(SilentRetryHooks, SkipsNextBreakHooks):
    """Retries a silent sensor 95 ms after the command, still without a break."""

    CHAINS = frozenset({"retry_time", "needs_break"})

    def silent_retry_time(self, master: Engine, prev: Attempt) -> float:
        """95 ms after the command, unbroken."""
        assert prev.command_end is not None
        self.skip_break = True
        return prev.command_end + LATE_RETRY


class NoBreakAfterMarkingHooks(GoldenHooks):
    """Sends a break only when the address changes, never for 87 ms of marking."""

    def needs_break(
        self, master: Engine, address: str, at: float, usual: Callable[[], bool]
    ) -> bool:
        """A break for a new address only."""
        return master.last_address is None or address != master.last_address


class NoBreakAfterMarkingToolRecorder(GoldenToolRecorder):
    """The golden engine (with :class:`NoBreakAfterMarkingHooks`) with no forced break in
    front of D0 after ttt either."""

    CHAINS = frozenset({"collect"})

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        return super().collect(m, force_break=False, max_index=max_index)


class EarlyDataHooks(GoldenHooks):
    """Without a service request, reads data after half of ttt instead of the whole."""

    def wait_for_data(
        self,
        master: Engine,
        m: Measurement,
        service_request: bool,
        usual: Callable[[], None],
    ) -> None:
        """Listen for half of ttt, stopping at a service request when one is awaited."""
        assert m.reply_end is not None and m.ttt is not None
        deadline = m.reply_end + m.ttt / 2
        while master.link.now() < deadline:
            got = master.link.receive(deadline, until=ends_line)
            m.waited_events.extend(got)
            if service_request and _is_service_request(m.waited_events, m.command.address):
                m.service_request_end = m.waited_events[-1].end
                return
            if not got:
                return


class StopsAfterD0ToolRecorder(GoldenToolRecorder):
    """Reads D0 (or DB0) only, whatever the announced count."""

    CHAINS = frozenset({"collect"})

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        return super().collect(m, force_break=force_break, max_index=0)


class WaitsForeverHooks(GoldenHooks):
    """Waits for the service request of aM!/aV! with no end: ttt is never counted (a logger
    loop written as "until the sensor calls"). A sensor that never sends one hangs it; the
    job is cut at its budget (recorder.job_time) and judged on what it sent."""

    def wait_for_data(
        self,
        master: Engine,
        m: Measurement,
        service_request: bool,
        usual: Callable[[], None],
    ) -> None:
        """The engine's wait for ttt; for a service request, a wait with no deadline."""
        if not service_request:
            usual()
            return
        while m.service_request_end is None:  # ends only through the job's cut
            m.waited_events.extend(master.link.receive(master.link.now() + 1.0, until=ends_line))
            m.service_request_end = _service_request_end(m.waited_events, m.command.address)


class _ZeroPaddedData(Command):
    """``aD010!``: a data command written with leading zeros (what R-5.1-04 forbids)."""

    def text(self) -> str:
        return f"{self.address}D{self.index:03d}!"


class LeadingZerosToolRecorder(GoldenToolRecorder):
    """Writes D10 and above with three digits (``0D010!``)."""

    def transact(self, command: Command | str, **kw: object) -> Exchange:
        if isinstance(command, Command) and command.kind is Kind.DATA and command.index >= 10:
            command = _ZeroPaddedData(command.address, Kind.DATA, index=command.index)
        return super().transact(command, **kw)  # type: ignore[arg-type]


class IgnoresCrcHooks(GoldenHooks):
    """Accepts a reply whose CRC does not match its text."""

    CHAINS = frozenset({"attempt"})

    def attempt(
        self,
        master: Engine,
        wire: bytes,
        address: str,
        command: Command | None,
        proceed: Callable[[], Attempt],
    ) -> Attempt:
        """The engine's attempt, taken as valid when only its CRC was wrong."""
        attempt = super().attempt(master, wire, address, command, proceed)
        if "should be" in attempt.reason:  # the engine's words for a CRC mismatch
            attempt = replace(attempt, reason="ok")
        return attempt


class BreakEveryTryHooks(GoldenHooks):
    """Never retries: after an unanswered or invalid reply it waits out a poll timeout, then
    sends a break and the command again (what a widely used logger library was seen to do,
    issue 20). With ``retries_per_sequence=0`` every repeat is such a new sequence."""

    CHAINS = frozenset({"attempt"})

    _failed: tuple[bytes, float] | None = None  # the wire text that failed, and when

    def attempt(
        self,
        master: Engine,
        wire: bytes,
        address: str,
        command: Command | None,
        proceed: Callable[[], Attempt],
    ) -> Attempt:
        """The engine's attempt, sent again only a poll timeout after it failed."""
        if self._failed is not None and self._failed[0] == wire:
            master.link.wait_until(self._failed[1] + POLL_TIMEOUT)
        attempt = super().attempt(master, wire, address, command, proceed)
        self._failed = None if attempt.ok else (wire, master.link.now())
        return attempt


class ResendAfterTimeoutHooks(SilentRetryHooks, SkipsNextBreakHooks):
    """Retries without a break, but only after a poll timeout: by then the sensor has been in
    standby for over a second and takes the command as no retry (issue 20's "D0 sent again
    after a 1.5 s poll timeout"). Every retry is timed so, after silence or a reply: its
    ``retry_time`` passes nothing on (no ``CHAINS`` for it), and its
    :meth:`silent_retry_time` refuses it beside a fault that times the retry after silence
    its own way (retry-too-early, retry-too-late)."""

    CHAINS = frozenset({"needs_break"})

    def retry_time(
        self,
        master: Engine,
        exchange: Exchange,
        sequence: int,
        per_sequence: int,
        usual: Callable[[], float],
    ) -> float:
        """A poll timeout after the last attempt ended, and no break before the retry."""
        return max(self.silent_retry_time(master, exchange.last), master.link.now())

    def silent_retry_time(self, master: Engine, prev: Attempt) -> float:
        """A poll timeout after ``prev`` ended, unbroken."""
        self.skip_break = True
        return prev.end + POLL_TIMEOUT


class LateD0AfterServiceRequestToolRecorder(GoldenToolRecorder):
    """After a service request waits 95 ms, then sends aD0! without a break (its hooks are
    :class:`SkipsNextBreakHooks`, or built on them)."""

    CHAINS = frozenset({"collect"})
    hooks: SkipsNextBreakHooks

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        if m.service_request_end is not None and not m.data:
            self.link.wait_until(m.service_request_end + LATE_D0)
            self.hooks.skip_break = True
        return super().collect(m, force_break=force_break, max_index=max_index)


class GappyCommandHooks(GoldenHooks):
    """Leaves ``gap`` of marking between the characters of every command."""

    gap = 3e-3

    def command_gap(self, master: Engine, gap: float) -> float:
        """At least ``self.gap`` between characters."""
        return max(gap, self.gap)


#: What a logger that keeps ttt in an 8-bit variable can count to (issue 20).
TTT_BITS = 8


class EightBitTttHooks(GoldenHooks):
    """Keeps the announced ttt in 8 bits: waits ``ttt % 256`` s (260 s becomes 4 s). It
    changes the figure only and passes the wait on (``CHAINS``): with d0-before-ttt the
    logger reads data after half of the cut ttt, with waits-forever-for-service-request it
    waits the cut ttt where no service request is due."""

    CHAINS = frozenset({"wait_for_data"})

    def wait_for_data(
        self,
        master: Engine,
        m: Measurement,
        service_request: bool,
        usual: Callable[[], None],
    ) -> None:
        """The engine's wait, for the announced ttt cut to 8 bits."""
        assert m.ttt is not None
        announced, m.ttt = m.ttt, m.ttt % (1 << TTT_BITS)
        try:
            super().wait_for_data(master, m, service_request, usual)
        finally:
            m.ttt = announced


@dataclass
class EightBitTttRecorder(GoldenRecorder):
    """The golden recorder with ttt kept in 8 bits for concurrent waits (and, with
    :class:`EightBitTttHooks`, for aM!-type ones)."""

    def _data_time(self, m: Measurement) -> float:
        assert m.reply_end is not None and m.ttt is not None
        margin = (self.policy or Policy.golden()).ttt_margin
        return m.reply_end + m.ttt % (1 << TTT_BITS) * self.ttt_fraction + margin


@dataclass
class SkipsTttZeroConcurrentRecorder(GoldenRecorder):
    """Starts concurrent measurements together but never collects one that announced
    ttt = 000 (a logger library that waits for ttt to count down past zero, issue 20, stuck
    there; here it gives up on that sensor rather than hang the run)."""

    def _concurrent(
        self, master: ToolRecorder, texts: tuple[str, ...], out: RecorderOutput
    ) -> None:
        started = [
            master.measure(parse_command(text), collect=False, wait="none") for text in texts
        ]
        pending = [m for m in started if m.count is not None and m.ttt]
        pending.sort(key=self._data_time)
        for m in pending:
            master.link.wait_until(self._data_time(m))
            master.collect(m, force_break=True)
        for text, m in zip(texts, started, strict=True):
            out.logged[text] = logged_values(m)


class DropsAfterParityHooks(GoldenHooks):
    """Takes a reply cut at its first parity error as valid, noting that it did (``cut``)."""

    CHAINS = frozenset({"attempt"})

    cut = False

    def attempt(
        self,
        master: Engine,
        wire: bytes,
        address: str,
        command: Command | None,
        proceed: Callable[[], Attempt],
    ) -> Attempt:
        """The engine's attempt; one invalid for parity becomes its characters before the bad
        one, valid."""
        attempt = super().attempt(master, wire, address, command, proceed)
        bad = [i for i, e in enumerate(attempt.reply_events) if not e.parity_ok]
        if attempt.ok or not bad or "parity" not in attempt.reason:
            return attempt
        self.cut = True
        return replace(attempt, reply_events=attempt.reply_events[: bad[0]], reason=OK)


class DropsAfterParityToolRecorder(GoldenToolRecorder):
    """Stops reading a reply at a character with a parity error and takes what came before
    it as the whole reply, and the measurement as collected: no retry, and the values before
    the bad character are what it logs (a logger library's read loop, issue 20). Its hooks
    are :class:`DropsAfterParityHooks`, or built on them."""

    hooks: DropsAfterParityHooks

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        """The golden collection one D command at a time, ending at a cut reply."""
        self.hooks.cut = False
        while m.count is not None and m.value_count < m.count:
            n, have = len(m.data), m.value_count
            limit = n if max_index is None else min(n, max_index)
            super().collect(m, force_break=force_break, max_index=limit)
            force_break = False
            if self.hooks.cut or len(m.data) == n or not m.data[-1].ok or m.value_count == have:
                break
        return m


class EngineRetryHooks(GoldenHooks):
    """The engine's own retry time, without the golden recorder's wait for a quiet line (no
    drain of a reply that may still be coming)."""

    retry_time = Hooks.retry_time


class TalksOverToolRecorder(GoldenToolRecorder):
    """The engine without any wait for a quiet line: neither the golden recorder's drain
    before a retry nor the engine's own listen before talk. It keeps only the turnaround
    after the last sensor character it has already seen, as the engine did before it
    listened (a retry goes out while the rest of a paused reply is still arriving). Its
    hooks are :class:`EngineRetryHooks`."""

    def clear_to_send(self, *, collide: bool = False) -> float:
        self.note_collisions()
        self.link.wait_until(self._earliest_transmit())
        return self.link.now()


class BandGapCommandHooks(GappyCommandHooks):
    """1.9 ms between command characters: only the ±0.40 ms tolerance the 1.66 ms limit does
    not have would make it pass."""

    gap = 1.9e-3


class WrongBaudLink:
    """The recorder's end of the sim bus, sending every character in ``char_time`` instead
    of 8.33 ms (a recorder at the wrong bit rate); everything else is the link's own."""

    def __init__(self, link: Link, char_time: float) -> None:
        # the job's link (recorder.job_time) stands in front of the sim bus's own
        if not isinstance(getattr(link, "bus", None), SimBus):
            raise TypeError("a wrong bit rate can only be played on the simulated bus")
        self._link = link
        self._char_time = char_time

    def __getattr__(self, name: str) -> object:
        return getattr(self._link, name)

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        events, time = [], self._link.now()
        for byte in wire:
            event = self._link.bus.tool_char(byte, time, self._char_time)
            events.append(event)
            time = event.end + gap
        return events


@dataclass
class WrongBaudRecorder(GoldenRecorder):
    """The golden recorder sending at a bit rate 4% too high (frames of 8.0 ms)."""

    CHAINS = frozenset({"__call__"})

    char_time: float = FAST_CHAR_TIME

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        return super().__call__(request, WrongBaudLink(link, self.char_time))  # type: ignore[arg-type]


@dataclass
class LacksCommandsRecorder(GoldenRecorder):
    """A logger that does not implement some command kinds, or cannot reach some addresses:
    asked for such commands, it skips them."""

    CHAINS = frozenset({"__call__"})

    lacks: frozenset[Kind] = frozenset()
    unreachable: str = ""  # addresses it cannot use (as the addressee or a new address)

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        kept = tuple(t for t in request.commands if self._can(parse_command(t)))
        return super().__call__(replace(request, commands=kept), link)

    def _can(self, command: Command) -> bool:
        targets = {command.address, command.new_address or ""}
        return command.kind not in self.lacks and not targets & set(self.unreachable)


@dataclass
class RewritingRecorder(GoldenRecorder):
    """A logger that changes what it is asked to send (``rewrite`` maps the wire text; an
    empty result is skipped) or adds commands of its own (``extra``, before the job).

    Outside transparent mode the job goes on whole to the golden recorder (concurrent
    measurements started together, a recorder before it in the order that changes the task
    seen): it used to go one command at a time, which measured two sensors' aC! one after
    the other (R-4.4.7-06's concurrent waits 2005..2005 ms instead of the golden 2005..2180)
    and lost interleaves-measurements' interleaving."""

    rewrite: Callable[[str], str] = field(default=lambda text: text)
    extra: str = ""  # addresses it polls with a! before the job
    preamble: str = ""  # text it sends after a break before the job

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        master = self.master_factory(link, self.policy or Policy.golden())
        for address in self.extra:
            master.transact(Command(address, Kind.ACKNOWLEDGE), force_break=True)
        if self.preamble:
            master.raw(self.preamble, break_first=True)
        if request.task is not Task.TRANSPARENT:
            kept = tuple(t for t in request.commands if self.rewrite(t))
            return super().__call__(replace(request, commands=kept), link)
        out = RecorderOutput()
        for text in request.commands:
            wire = self.rewrite(text)
            if wire:
                # a break of its own, or the engine's break rules (True or None)
                ex = master.raw(wire, break_first=self.transparent_break or None)
                out.relayed[text] = ex.reply_text if ex.answered else ""
        return out


@dataclass
class InterleavingRecorder(GoldenRecorder):
    """Asked to measure several sensors with aM!, starts them all before collecting any, as
    if they were concurrent measurements. It changes the task and passes the whole job on
    (``CHAINS``): the recorders it passes it to keep a job whole (the rewriting one used to
    split it per command, and seed 27 drew crlf-wake-up + interleaves-measurements with the
    interleaving lost)."""

    CHAINS = frozenset({"__call__"})

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        if request.task is Task.MEASURE and len({t[:1] for t in request.commands}) > 1:
            request = replace(request, task=Task.CONCURRENT)
        return super().__call__(request, link)


@dataclass
class MislogsRecorder(GoldenRecorder):
    """Collects every value as the golden recorder does, then writes some down wrong: each
    of ``spoils`` (``spoil(command, values)``) in :data:`SPOIL_ORDER` turns what it logs for
    each measurement command. A set, so the mislogging faults compose (a logger that drops
    the sign may cut the field too): the knobs unite (compose._merge_values)."""

    CHAINS = frozenset({"__call__"})

    spoils: frozenset[Callable[[Command, list[str]], list[str]]] = frozenset()

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        out = super().__call__(request, link)
        spoils = [s for s in SPOIL_ORDER if s in self.spoils]
        for text, values in out.logged.items():
            command = parse_command(text)
            for spoil in spoils:
                values = spoil(command, values)
            out.logged[text] = values
        return out


#: Characters a logger with a fixed field per value keeps (``+1013.25`` becomes ``+1013.2``).
FIELD_WIDTH = 7


def _unsigned(command: Command, values: list[str]) -> list[str]:
    return [v.lstrip("-") for v in values]


def _cut(command: Command, values: list[str]) -> list[str]:
    return [v[:FIELD_WIDTH] for v in values]


def _last_concurrent_lost(command: Command, values: list[str]) -> list[str]:
    return values[:-1] if command.kind is Kind.CONCURRENT else values


#: The order a logger's spoils act in: the value dropped from the record, then each value
#: formatted without its sign, then written into its fixed field.
SPOIL_ORDER = (_last_concurrent_lost, _unsigned, _cut)


def _is_service_request(events: list, address: str) -> bool:
    return decode_7e1(events[-3:]) == service_request(address)


def _lacks(**knobs: object) -> Parts:
    return Parts(recorder=LacksCommandsRecorder, knobs=knobs)


def _rewriting(**knobs: object) -> Parts:
    return Parts(recorder=RewritingRecorder, knobs=knobs)


def _mislogs(**knobs: object) -> Parts:
    return Parts(recorder=MislogsRecorder, knobs=knobs)


def _without_extended_address(text: str) -> str:
    """``XSN!`` for ``0XSN!``: an extended command sent without its address."""
    return text[1:] if text[1:2] == "X" else text


@dataclass(frozen=True)
class RecorderFault:
    name: str
    description: str
    violates: tuple[str, ...]
    #: where it departs from the golden recorder (:mod:`conformance.recorder.compose`)
    parts: Parts = field(compare=False)
    #: collateral INCONCLUSIVEs the fault declares (see the sensor faults' field)
    inconclusive: tuple[str, ...] = ()

    def make(self) -> GoldenRecorder:
        """The golden recorder with this fault alone."""
        return compose(((self.name, self.parts),))


_FAULTS = (
    RecorderFault(
        "no-retries",
        "Sends each command once: no retry, no repeated sequence, so a silent sensor, a bad "
        "CRC or a garbled reply ends the job. With no retry at all, whether a retry waits for "
        "an invalid reply to end (R-7.2-06) cannot be seen.",
        ("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-04", "R-7.2-05", "R-4.4.12-07"),
        Parts(policy={"retries_per_sequence": 0, "sequences": 1}),
        inconclusive=("R-7.2-06",),
    ),
    RecorderFault(
        "retries-with-break",
        f"Never retries without a break: after no reply or an invalid one it waits "
        f"{POLL_TIMEOUT} s, then sends a break and the command again, three times in all. "
        "Those repeats are new sequences, not retries: no retry is seen (R-7.2-01/-02/-05), no "
        "sequence has its two retries (R-7.2-03), and with no break+command+retries sequence "
        "on the wire whether it would repeat one (R-7.2-04, SHOULD) or wait for an invalid "
        "reply to end before a retry (R-7.2-06) cannot be seen.",
        ("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-05"),
        Parts(policy={"retries_per_sequence": 0, "sequences": 3}, hooks=BreakEveryTryHooks),
        inconclusive=("R-7.2-04", "R-7.2-06"),
    ),
    RecorderFault(
        "breaks-over-long-reply",
        "Reads at most 40 characters of a reply (a fixed receive buffer) and never retries "
        "without a break: past the 40th it gives the reply up and at once sends a break and the "
        "command again over the rest, so it never waits for a long reply to complete "
        "(R-7.2-06: aC9!'s and aHA!'s 75-character D0 replies). Those replies and pause-once's "
        "aM2! data are never read whole: values lost (R-4.4-02, R-5.4-01), aC9! and aHA! given "
        "up at D0 (R-4.4.8-05, R-4.4.7-07, R-5.1-04); and no retry is seen (R-7.2-01/-02/-03/"
        "-05), nor a break+command+retries sequence repeated (R-7.2-04).",
        (
            "R-7.2-06",
            "R-4.4-02",
            "R-5.4-01",
            "R-4.4.8-05",
            "R-4.4.7-07",
            "R-5.1-04",
            "R-7.2-01",
            "R-7.2-02",
            "R-7.2-03",
            "R-7.2-05",
        ),
        Parts(
            policy={
                "max_reply_chars": 40,
                "retries_per_sequence": 0,
                "max_hold": 0.0,
                "post_break_marking": 20e-3,
            }
        ),
        inconclusive=("R-7.2-04",),
    ),
    RecorderFault(
        "resends-after-timeout",
        f"Sends a command again without a break only {POLL_TIMEOUT} s after no reply or an "
        "invalid one, long after the sensor's 100 ms to standby: not a retry (R-7.2-01/-02/"
        "-05), no sequence with two retries (R-7.2-03), and a command after 87 ms of marking "
        "without a break (R-7.0-17).",
        ("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-05", "R-7.0-17"),
        Parts(hooks=ResendAfterTimeoutHooks),
        inconclusive=("R-7.2-04", "R-7.2-06"),
    ),
    RecorderFault(
        "retry-too-early",
        f"The first retry after no reply starts {EARLY_RETRY * 1e3:.0f} ms after the command. "
        "Against the sensor that starts its replies 15.0 ms after the command (scenario "
        "reply-at-window-edge) that retry runs into the reply, and on the line its characters "
        "come apart (R-7.0-13): what R-7.2-02's 16.67 ms is there to prevent.",
        ("R-7.2-02", "R-7.0-13"),
        Parts(policy={"first_char_timeout": 10e-3}, hooks=EarlyRetryHooks),
    ),
    RecorderFault(
        "retry-too-late",
        f"The first retry after no reply starts {LATE_RETRY * 1e3:.0f} ms after the command, "
        "without a break.",
        ("R-7.2-02", "R-7.0-17"),
        Parts(hooks=LateRetryHooks),
    ),
    RecorderFault(
        "no-break-after-87ms",
        "Breaks only for a new address: aD0! after ttt goes out without a break.",
        ("R-7.0-17", "R-4.4.5-05"),
        Parts(hooks=NoBreakAfterMarkingHooks, master=NoBreakAfterMarkingToolRecorder),
    ),
    RecorderFault(
        "d0-before-ttt",
        "Without a service request, asks for data after half of ttt.",
        ("R-4.4.5-04", "R-4.4.5-07", "R-4.4.7-06"),
        Parts(hooks=EarlyDataHooks, knobs={"ttt_fraction": 0.5}),
    ),
    RecorderFault(
        "ignores-service-request",
        "Waits the full ttt after aM!/aV! even when the service request came long before. The "
        "standard gives no figure for how soon aD0! follows the request (and lets a recorder "
        "wait the whole ttt), so past the tool's 0.5 s this is a WARN (decision T1).",
        ("R-4.4.5-05",),
        Parts(knobs={"wait": "ttt"}),
    ),
    RecorderFault(
        "waits-forever-for-service-request",
        "Waits for the service request after aM!/aV! with no end, never counting ttt down: "
        "a sensor that sends none hangs it until its job is cut at the stated budget. No aD0! "
        "in the seconds from ttt to the cut (R-4.4.5-05); whether it would then have collected "
        "the values (R-4.4.8-05) the cut leaves unobserved. The rules over every transmission "
        "still PASS on what it sent, while the rules about that job itself cannot PASS on a "
        "job that never ended.",
        ("R-4.4.5-05",),
        Parts(hooks=WaitsForeverHooks),
        inconclusive=("R-4.4.5-04", "R-4.4.5-06", "R-4.4.5-07", "R-4.4.8-05"),
    ),
    RecorderFault(
        "stops-after-d0",
        "Reads D0 (DB0) only, so values in D1 and later are never collected.",
        ("R-4.4.8-05", "R-4.4.7-07", "R-5.1-04", "R-5.2-08"),
        Parts(master=StopsAfterD0ToolRecorder),
    ),
    RecorderFault(
        "leading-zeros-after-d9",
        "After aHA! writes D10 and later as aD010!.",
        ("R-5.1-04",),
        Parts(master=LeadingZerosToolRecorder),
    ),
    RecorderFault(
        "ignores-bad-crc",
        "Accepts a reply whose CRC does not match (no retry, wrong value logged).",
        ("R-4.4.12-07", "R-7.2-05"),
        Parts(hooks=IgnoresCrcHooks),
    ),
    RecorderFault(
        "short-break",
        "Breaks last 10 ms (at least 12 ms are due): spacing too short to be a break, so its "
        "commands go without one (R-7.0-17).",
        ("R-7.0-02", "R-7.0-17"),
        Parts(policy={"break_duration": 10e-3}),
    ),
    RecorderFault(
        "no-concurrent",
        "Has no aC!-type commands: asked for aC!, aCn! or aCC!, it sends nothing. With no "
        "concurrent measurement on the wire, its waits (R-4.4.7-06) and how many of its values "
        "are stored (R-4.4.7-07) cannot be seen.",
        ("R-4.4.7-08", "R-4.4-02"),
        _lacks(lacks=frozenset({Kind.CONCURRENT})),
        inconclusive=("R-4.4.7-06", "R-4.4.7-07"),
    ),
    RecorderFault(
        "no-high-volume",
        "A v1.4 recorder without aHA!/aHB!: asked for them, it sends nothing. How it would read "
        "past D9 (R-5.1-04) or binary packets (R-5.2-08) then cannot be seen.",
        ("R-5.4-01",),
        _lacks(lacks=frozenset({Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY})),
        inconclusive=("R-5.1-04", "R-5.2-08"),
    ),
    RecorderFault(
        "drops-metadata",
        "Transparent mode drops identify and metadata commands (aIM!, aIM_001!...) instead of "
        "passing them on.",
        ("R-6.3-01", "R-4.4.14-02"),
        _lacks(lacks=frozenset({Kind.METADATA, Kind.IDENTIFY_MEASUREMENT})),
    ),
    RecorderFault(
        "multiline-cut-short",
        "Takes multi-line text without ETX as finished 50 ms after a line, not 150 ms.",
        ("R-4.4.13.1-04",),
        Parts(policy={"line_wait": 50e-3}),
    ),
    RecorderFault(
        "late-d0-without-break",
        f"Sends aD0! {LATE_D0 * 1e3:.0f} ms after the service request without a break (87 ms "
        "is the limit; after it a break is due, which R-7.0-17 also demands).",
        ("R-7.1-01", "R-7.0-17"),
        Parts(hooks=SkipsNextBreakHooks, master=LateD0AfterServiceRequestToolRecorder),
    ),
    RecorderFault(
        "fast-baud",
        f"Sends at {10 / FAST_CHAR_TIME:.0f} baud: every command character lasts "
        f"{FAST_CHAR_TIME * 1e3:.2f} ms, not 8.33 ms (decision A14 allows 2%).",
        ("R-4.1-01",),
        Parts(recorder=WrongBaudRecorder),
    ),
    RecorderFault(
        "gappy-commands",
        "Leaves 3 ms of marking between the characters of every command (1.66 ms at most).",
        ("R-7.0-13",),
        Parts(hooks=GappyCommandHooks),
        inconclusive=("R-4.1-01",),  # no back-to-back characters: rate and gaps inseparable
    ),
    RecorderFault(
        "command-gap-in-tolerance",
        "Leaves 1.9 ms between command characters: over 1.66 ms, inside the ±0.40 ms that "
        "this limit does not grant.",
        ("R-7.0-13", "R-7.0-01"),
        Parts(hooks=BandGapCommandHooks),
        inconclusive=("R-4.1-01",),
    ),
    RecorderFault(
        "transparent-no-break",
        "Transparent mode sends host commands without a break of its own.",
        ("R-4.4.14-01",),
        Parts(knobs={"transparent_break": False}),
    ),
    RecorderFault(
        "transparent-drops-address",
        "Transparent mode sends extended commands without their address (XSN! for 0XSN!). "
        "No sensor answers those, so no multi-line text comes whose end R-4.4.13.1-04 judges.",
        ("R-4.4.13-03", "R-4.4.14-02"),
        _rewriting(rewrite=_without_extended_address),
        inconclusive=("R-4.4.13.1-04",),
    ),
    RecorderFault(
        "addresses-0-4-only",
        "Can only use addresses 0-4: commands to sensors at 5-9, or moving one there, are skipped.",
        ("R-4.3-03", "R-4.4-02"),
        _lacks(unreachable="56789"),
    ),
    RecorderFault(
        "polls-dollar",
        "Before each job it polls '$!', as if '$' were a sensor address.",
        ("R-4.3-01", "R-4.3-04"),
        _rewriting(extra="$"),
    ),
    RecorderFault(
        "talks-over-reply",
        "Retries as soon as a reply pauses, while the sensor may still be sending (the engine "
        "without the golden recorder's wait for a quiet line). Its retry collides with the "
        "rest of the reply, and on the line its characters come apart (R-7.0-13).",
        ("R-7.2-06", "R-7.0-13"),
        Parts(hooks=EngineRetryHooks, master=TalksOverToolRecorder),
    ),
    RecorderFault(
        "interleaves-measurements",
        "Starts aM! on one sensor, then aM! on another before collecting the first one's data: "
        "it takes the line while the first one's service request may come (R-4.4.5-07) and "
        "reads its data only after ttt, not on that request (R-4.4.5-05).",
        ("R-4.4.5-06", "R-4.4.5-07", "R-4.4.5-05"),
        Parts(recorder=InterleavingRecorder),
    ),
    RecorderFault(
        "crlf-wake-up",
        "Before each job it sends a break and CR LF, a modem-style wake-up that is no command.",
        ("R-4.2-01", "R-4.4-04", "R-4.3-01"),
        _rewriting(preamble="\r\n"),
    ),
    RecorderFault(
        "short-reply-timeout",
        f"Takes a reply that has not started {SHORT_REPLY_TIMEOUT * 1e3:.0f} ms after the "
        "command as silence, though a sensor may start its reply up to 15.40 ms after the "
        "command (R-7.0-10). Against the sensor answering at 15.0 ms (scenario "
        "reply-at-window-edge) it sends the command again after each whole reply, then, its "
        "retries spent, a break 10 ms after the command that cuts the next reply off: no "
        "retry without a break after that lost reply (R-7.2-01/-02/-05), no sequence with "
        "two retries (R-7.2-03), and the measurement's data never collected (R-4.4.8-05). "
        "The tolerance sweep (--sweep reply) shows where it gives up.",
        ("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-05", "R-4.4.8-05"),
        Parts(policy={"first_char_timeout": SHORT_REPLY_TIMEOUT}),
    ),
    RecorderFault(
        "ttt-8-bit",
        "Keeps the announced ttt in 8 bits (ttt % 256): told ttt = 260 s it waits 4 s, then "
        "sends a break and aD0! before the service request (which comes after 6 s) and long "
        "before ttt, taking the line while that request could still come.",
        ("R-4.4.5-04", "R-4.4.5-07"),
        Parts(hooks=EightBitTttHooks, recorder=EightBitTttRecorder),
    ),
    RecorderFault(
        "concurrent-ttt-zero-stalls",
        "Never collects a concurrent measurement that announced ttt = 000: of two sensors "
        "measured together it reads only the one with ttt > 0, none of the other's values.",
        ("R-4.4.8-05", "R-4.4.7-08"),
        Parts(recorder=SkipsTttZeroConcurrentRecorder),
    ),
    RecorderFault(
        "drops-after-parity-error",
        "Stops reading a reply at a character with a parity error and takes what came before "
        "it as the reply and the measurement as collected: no retry (R-7.2-05), and it logs "
        "the values before the bad character (+22.15 +10 for +22.15 +1013.2 +45.7), values "
        "of a reply that was not valid (R-4.4-02).",
        ("R-7.2-05", "R-4.4-02"),
        Parts(hooks=DropsAfterParityHooks, master=DropsAfterParityToolRecorder),
    ),
    RecorderFault(
        "short-marking",
        "Leaves 5 ms of marking after the break before the command (8.33 ms are due).",
        ("R-7.0-06",),
        Parts(policy={"post_break_marking": 5e-3}),
    ),
)


_LOGGING = (
    RecorderFault(
        "logs-without-sign",
        "Collects every value, then logs it without its sign (-3.75 becomes 3.75): every "
        "negative value logged from aM2!, aC! and the HB packets is wrong.",
        ("R-4.4-02", "R-5.4-01"),
        _mislogs(spoils=frozenset({_unsigned})),
    ),
    RecorderFault(
        "truncates-values",
        f"Logs each value in a field of {FIELD_WIDTH} characters, so longer values lose digits "
        "(+1013.25 becomes +1013.2, +1234.567 becomes +1234.5), in aM2!, aR1!, aHA! and aHB! "
        "data.",
        ("R-4.4-02", "R-5.4-01"),
        _mislogs(spoils=frozenset({_cut})),
    ),
    RecorderFault(
        "loses-last-concurrent-value",
        "Logs every concurrent measurement (aC!, aCn!, aCC!) without its last value: 98 of "
        "aC9!'s 99 values, all of which it read from the sensor.",
        ("R-4.4-02",),
        _mislogs(spoils=frozenset({_last_concurrent_lost})),
    ),
)

RECORDER_FAULTS: dict[str, RecorderFault] = {f.name: f for f in (*_FAULTS, *_LOGGING)}


def faulty_recorder(names: tuple[str, ...]) -> GoldenRecorder:
    """The golden recorder with the named faults' deviations at once (KeyError for an unknown
    name; :class:`~conformance.recorder.compose.Refused` for faults that cannot compose)."""
    unknown = [n for n in names if n not in RECORDER_FAULTS]
    if unknown:
        raise KeyError(", ".join(unknown))
    return compose([(n, RECORDER_FAULTS[n].parts) for n in dict.fromkeys(names)])


def composition_conflict(names: tuple[str, ...]) -> str | None:
    """Why the named faults cannot be one recorder, or None when they compose."""
    return conflict([(n, RECORDER_FAULTS[n].parts) for n in dict.fromkeys(names)])
