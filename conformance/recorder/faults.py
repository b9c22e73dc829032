"""Faulty golden recorders: the recorder role's fault-detection matrix (design.md 5).

Each fault is the golden recorder with one deviation (a policy value, a small Master
subclass, or a recorder knob) and the requirements it breaks. The matrix test runs the whole
recorder suite against each and demands that exactly those requirements come out FAIL/WARN.
Where one deviation honestly breaks several rules (a recorder that never retries also never
retries on a bad CRC), all of them are declared, with the reason in the description.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from ..links.base import Link
from ..master import Master, Measurement, Policy
from ..master.records import Attempt, Exchange
from ..master.validity import ends_line
from ..protocol.commands import Command, Kind, parse_command
from ..sim.bus import SimLink
from ..transcript import Event, decode_7e1
from .golden import GoldenMaster, GoldenRecorder
from .request import RecorderOutput, Request

EARLY_RETRY = 12e-3  # s after the command: inside the 16.67 ms that R-7.2-02 forbids
LATE_RETRY = 95e-3  # s after the command: past the 87 ms of R-7.2-02
LATE_D0 = 95e-3  # s after the service request: past the 87 ms of R-7.1-01
FAST_CHAR_TIME = 8.0e-3  # s per frame: 1250 baud, 4% fast (A14 allows 2%)


class EarlyRetryMaster(GoldenMaster):
    """Retries a silent sensor 12 ms after the command (the first retry of each sequence)."""

    def _retry_time(self, exchange: Exchange, sequence: int, per_sequence: int) -> float:
        prev = exchange.last
        first_retry = not any(a.sequence == sequence and a.retry for a in exchange.attempts)
        if first_retry and not prev.reply_events and prev.command_end is not None:
            return max(prev.command_end + EARLY_RETRY, self.link.now())
        return super()._retry_time(exchange, sequence, per_sequence)


class LateRetryMaster(GoldenMaster):
    """Retries a silent sensor 95 ms after the command, still without a break."""

    _skip_break = False

    def _retry_time(self, exchange: Exchange, sequence: int, per_sequence: int) -> float:
        prev = exchange.last
        first_retry = not any(a.sequence == sequence and a.retry for a in exchange.attempts)
        if first_retry and not prev.reply_events and prev.command_end is not None:
            self._skip_break = True
            return max(prev.command_end + LATE_RETRY, self.link.now())
        return super()._retry_time(exchange, sequence, per_sequence)

    def _needs_break(self, address: str, at: float) -> bool:
        if self._skip_break:
            self._skip_break = False
            return False
        return super()._needs_break(address, at)


class NoBreakAfterMarkingMaster(GoldenMaster):
    """Sends a break only when the address changes, never for 87 ms of marking."""

    def _needs_break(self, address: str, at: float) -> bool:
        return self.last_address is None or address != self.last_address

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        return super().collect(m, force_break=False, max_index=max_index)


class EarlyDataMaster(GoldenMaster):
    """Without a service request, reads data after half of ttt instead of the whole."""

    def _wait_for_data(self, m: Measurement, *, service_request: bool) -> None:
        assert m.reply_end is not None and m.ttt is not None
        deadline = m.reply_end + m.ttt / 2
        while self.link.now() < deadline:
            got = self.link.receive(deadline, until=ends_line)
            m.waited_events.extend(got)
            if service_request and _is_service_request(m.waited_events, m.command.address):
                m.service_request_end = m.waited_events[-1].end
                return
            if not got:
                return


class StopsAfterD0Master(GoldenMaster):
    """Reads D0 (or DB0) only, whatever the announced count."""

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        return super().collect(m, force_break=force_break, max_index=0)


class _ZeroPaddedData(Command):
    """``aD010!``: a data command written with leading zeros (what R-5.1-04 forbids)."""

    def text(self) -> str:
        return f"{self.address}D{self.index:03d}!"


class LeadingZerosMaster(GoldenMaster):
    """Writes D10 and above with three digits (``0D010!``)."""

    def transact(self, command: Command | str, **kw: object) -> Exchange:
        if isinstance(command, Command) and command.kind is Kind.DATA and command.index >= 10:
            command = _ZeroPaddedData(command.address, Kind.DATA, index=command.index)
        return super().transact(command, **kw)  # type: ignore[arg-type]


class IgnoresCrcMaster(GoldenMaster):
    """Accepts a reply whose CRC does not match its text."""

    def _attempt(self, *args: object, **kw: object) -> Attempt:
        attempt = super()._attempt(*args, **kw)  # type: ignore[arg-type]
        if "should be" in attempt.reason:  # the engine's words for a CRC mismatch
            attempt = replace(attempt, reason="ok")
        return attempt


class LateD0AfterServiceRequestMaster(GoldenMaster):
    """After a service request waits 95 ms, then sends aD0! without a break."""

    _no_break_once = False

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        if m.service_request_end is not None and not m.data:
            self.link.wait_until(m.service_request_end + LATE_D0)
            self._no_break_once = True
        return super().collect(m, force_break=force_break, max_index=max_index)

    def _needs_break(self, address: str, at: float) -> bool:
        if self._no_break_once:
            self._no_break_once = False
            return False
        return super()._needs_break(address, at)


class WrongBaudLink:
    """The recorder's end of the sim bus, sending every character in ``char_time`` instead
    of 8.33 ms (a recorder at the wrong bit rate); everything else is the link's own."""

    def __init__(self, link: Link, char_time: float) -> None:
        if not isinstance(link, SimLink):
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

    char_time: float = FAST_CHAR_TIME

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        return super().__call__(request, WrongBaudLink(link, self.char_time))  # type: ignore[arg-type]


@dataclass
class LacksCommandsRecorder(GoldenRecorder):
    """A logger that does not implement some command kinds: asked for them, it skips them."""

    lacks: frozenset[Kind] = frozenset()

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        kept = tuple(t for t in request.commands if parse_command(t).kind not in self.lacks)
        return super().__call__(replace(request, commands=kept), link)


def _is_service_request(events: list, address: str) -> bool:
    return decode_7e1(events[-3:]) == f"{address}\r\n"


def _with_master(cls: type[Master]) -> Callable[[Link, Policy], Master]:
    return lambda link, policy: cls(link, policy)


@dataclass(frozen=True)
class RecorderFault:
    name: str
    description: str
    violates: tuple[str, ...]
    make: Callable[[], GoldenRecorder] = field(compare=False)
    #: collateral INCONCLUSIVEs the fault declares (see the sensor faults' field)
    inconclusive: tuple[str, ...] = ()


_GOLDEN = Policy.golden()

_FAULTS = (
    RecorderFault(
        "no-retries",
        "Sends each command once: no retry, no repeated sequence, so a silent sensor, a bad "
        "CRC or a garbled reply ends the job. With no retry at all, whether a retry waits for "
        "an invalid reply to end (R-7.2-06) cannot be seen.",
        ("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-04", "R-7.2-05", "R-4.4.12-07"),
        lambda: GoldenRecorder(_GOLDEN.but(retries_per_sequence=0, sequences=1)),
        inconclusive=("R-7.2-06",),
    ),
    RecorderFault(
        "retry-too-early",
        f"The first retry after no reply starts {EARLY_RETRY * 1e3:.0f} ms after the command.",
        ("R-7.2-02",),
        lambda: GoldenRecorder(
            _GOLDEN.but(first_char_timeout=10e-3), _with_master(EarlyRetryMaster)
        ),
    ),
    RecorderFault(
        "retry-too-late",
        f"The first retry after no reply starts {LATE_RETRY * 1e3:.0f} ms after the command, "
        "without a break.",
        ("R-7.2-02", "R-7.0-17"),
        lambda: GoldenRecorder(_GOLDEN, _with_master(LateRetryMaster)),
    ),
    RecorderFault(
        "no-break-after-87ms",
        "Breaks only for a new address: aD0! after ttt goes out without a break.",
        ("R-7.0-17", "R-4.4.5-05"),
        lambda: GoldenRecorder(_GOLDEN, _with_master(NoBreakAfterMarkingMaster)),
    ),
    RecorderFault(
        "d0-before-ttt",
        "Without a service request, asks for data after half of ttt.",
        ("R-4.4.5-04", "R-4.4.5-07", "R-4.4.7-06"),
        lambda: GoldenRecorder(_GOLDEN, _with_master(EarlyDataMaster), ttt_fraction=0.5),
    ),
    RecorderFault(
        "ignores-service-request",
        "Waits the full ttt after aM!/aV! even when the service request came long before.",
        ("R-4.4.5-05",),
        lambda: GoldenRecorder(_GOLDEN, wait="ttt"),
    ),
    RecorderFault(
        "stops-after-d0",
        "Reads D0 (DB0) only, so values in D1 and later are never collected.",
        ("R-4.4.8-05", "R-4.4.7-07", "R-5.1-04", "R-5.2-08"),
        lambda: GoldenRecorder(_GOLDEN, _with_master(StopsAfterD0Master)),
    ),
    RecorderFault(
        "leading-zeros-after-d9",
        "After aHA! writes D10 and later as aD010!.",
        ("R-5.1-04",),
        lambda: GoldenRecorder(_GOLDEN, _with_master(LeadingZerosMaster)),
    ),
    RecorderFault(
        "ignores-bad-crc",
        "Accepts a reply whose CRC does not match (no retry, wrong value logged).",
        ("R-4.4.12-07", "R-7.2-05"),
        lambda: GoldenRecorder(_GOLDEN, _with_master(IgnoresCrcMaster)),
    ),
    RecorderFault(
        "short-break",
        "Breaks last 10 ms (at least 12 ms are due).",
        ("R-7.0-02",),
        lambda: GoldenRecorder(_GOLDEN.but(break_duration=10e-3)),
    ),
    RecorderFault(
        "no-concurrent",
        "Has no aC!-type commands: asked for aC!, aCn! or aCC!, it sends nothing. With no "
        "concurrent measurement on the wire, its waits (R-4.4.7-06) and how many of its values "
        "are stored (R-4.4.7-07) cannot be seen.",
        ("R-4.4.7-08", "R-4.4-02"),
        lambda: LacksCommandsRecorder(lacks=frozenset({Kind.CONCURRENT})),
        inconclusive=("R-4.4.7-06", "R-4.4.7-07"),
    ),
    RecorderFault(
        "no-high-volume",
        "A v1.4 recorder without aHA!/aHB!: asked for them, it sends nothing. How it would read "
        "past D9 (R-5.1-04) or binary packets (R-5.2-08) then cannot be seen.",
        ("R-5.4-01",),
        lambda: LacksCommandsRecorder(
            lacks=frozenset({Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY})
        ),
        inconclusive=("R-5.1-04", "R-5.2-08"),
    ),
    RecorderFault(
        "drops-metadata",
        "Transparent mode drops identify and metadata commands (aIM!, aIM_001!...) instead of "
        "passing them on.",
        ("R-6.3-01", "R-4.4.14-02"),
        lambda: LacksCommandsRecorder(
            lacks=frozenset({Kind.METADATA, Kind.IDENTIFY_MEASUREMENT})
        ),
    ),
    RecorderFault(
        "multiline-cut-short",
        "Takes multi-line text without ETX as finished 50 ms after a line, not 150 ms.",
        ("R-4.4.13.1-04",),
        lambda: GoldenRecorder(_GOLDEN.but(line_wait=50e-3)),
    ),
    RecorderFault(
        "late-d0-without-break",
        f"Sends aD0! {LATE_D0 * 1e3:.0f} ms after the service request without a break (87 ms "
        "is the limit; after it a break is due, which R-7.0-17 also demands).",
        ("R-7.1-01", "R-7.0-17"),
        lambda: GoldenRecorder(_GOLDEN, _with_master(LateD0AfterServiceRequestMaster)),
    ),
    RecorderFault(
        "fast-baud",
        f"Sends at {10 / FAST_CHAR_TIME:.0f} baud: every command character lasts "
        f"{FAST_CHAR_TIME * 1e3:.2f} ms, not 8.33 ms (decision A14 allows 2%).",
        ("R-4.1-01",),
        lambda: WrongBaudRecorder(),
    ),
    RecorderFault(
        "short-marking",
        "Leaves 5 ms of marking after the break before the command (8.33 ms are due).",
        ("R-7.0-06",),
        lambda: GoldenRecorder(_GOLDEN.but(post_break_marking=5e-3)),
    ),
)

RECORDER_FAULTS: dict[str, RecorderFault] = {f.name: f for f in _FAULTS}


def faulty_recorder(names: tuple[str, ...]) -> GoldenRecorder:
    """The golden recorder with one fault (several are not composable: each replaces it)."""
    if not names:
        return GoldenRecorder()
    if len(names) > 1:
        raise ValueError("recorder faults do not compose; choose one")
    unknown = [n for n in names if n not in RECORDER_FAULTS]
    if unknown:
        raise KeyError(", ".join(unknown))
    return RECORDER_FAULTS[names[0]].make()
