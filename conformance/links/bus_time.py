"""How much bus time a run could not have avoided, from its transcript.

On a real-time link every millisecond the tool spends is a millisecond of the user's bench
time, so the run reports the least time any recorder would have needed for the same
exchanges next to the wall time it took. The lower bound is the union of:

- every frame on the wire (8.33 ms each, either side) and every break as held;
- the 8.33 ms of marking that must follow each break (R-7.0-06);
- every stretch of marking that ended with the DUT starting to talk: its response delays,
  its service-request waits, its gaps inside a reply (the DUT's time, not the tool's);
- after the DUT's last character, the 7.5 ms it may still hold the line (R-7.0-11); after a
  command that got no reply, the 16.67 ms before a retry may start (R-7.2-02);
- the ttt a measurement announced, counted from the end of its ``atttn`` reply up to ttt
  or the tool's choice to end it sooner: for an M-type or V measurement the next break (an
  abort, or giving up), for a concurrent one (C, CC, Cn, CCn, HA, HB) the next command to the
  same sensor. A break does not end a concurrent measurement (R-4.4.7-05): a recorder that
  breaks to talk to other sensors meanwhile still waits for ttt before it reads the data.

Anything beyond that (retry spacing, listening windows for silence, patience past limits,
scheduling latency) is the tool's overhead.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from ..protocol.commands import CommandError, parse_command
from ..protocol.responses import measurement_digits, parse_measurement_reply
from ..protocol.timing import CHAR_TIME, MARKING_AFTER_BREAK, RELEASE_LINE, RETRY_MIN
from ..transcript import TOOL, Event, EventKind, decode_7e1


@dataclass(frozen=True)
class BusTime:
    lower_bound: float  # s the exchanges needed at the very least
    span: float  # s from the first to the last event on the wire
    frames: int
    breaks: int

    def to_json(self) -> dict[str, float | int]:
        return {
            "bus_lower_bound_s": round(self.lower_bound, 3),
            "bus_span_s": round(self.span, 3),
            "frames": self.frames,
            "breaks": self.breaks,
        }


def bus_time(events: Iterable[Event]) -> BusTime:
    wire = [e for e in events if e.kind is not EventKind.NOTE]
    if not wire:
        return BusTime(0.0, 0.0, 0, 0)
    wire.sort(key=lambda e: e.start)
    spans: list[tuple[float, float]] = []
    frames = breaks = 0
    for e in wire:
        if e.kind is EventKind.BREAK:
            breaks += 1
            spans.append((e.start, e.end + MARKING_AFTER_BREAK))
        else:
            frames += 1
            spans.append((e.start, e.start + CHAR_TIME))
    previous = wire[0]
    previous_end = previous.end
    for e in wire[1:]:
        if e.start > previous_end:
            spans.append(
                (previous_end, previous_end + _forced_gap(previous, e, e.start - previous_end))
            )
        if e.end >= previous_end:
            previous, previous_end = e, e.end
    spans += _announced_waits(wire)
    return BusTime(_union(spans), wire[-1].end - wire[0].start, frames, breaks)


def _forced_gap(before: Event, after: Event, gap: float) -> float:
    """How much of the marking between two events no recorder could have skipped."""
    if after.kind is EventKind.CHAR and after.origin != TOOL:
        return gap  # the DUT chose when to talk (response delay, service request, gaps)
    if before.origin != TOOL:
        return min(gap, RELEASE_LINE)  # the DUT may hold the line after its last stop bit
    if before.kind is EventKind.CHAR and before.char7 == ord("!"):
        return min(gap, RETRY_MIN)  # no reply: the earliest a retry may start
    return 0.0


@dataclass
class _Wait:
    """The ttt a measurement announced: from ``start`` (the end of ``atttn``) to ``end``."""

    start: float
    end: float
    address: str
    concurrent: bool

    def cut(self, at: float) -> None:
        """The tool ended the wait at ``at`` (never before it began)."""
        self.end = min(self.end, max(self.start, at))


def _announced_waits(wire: list[Event]) -> list[tuple[float, float]]:
    """[end of ``atttn``, end + ttt] for each measurement the DUT started, cut where the tool
    chose to end it sooner (see the module docstring)."""
    waits: list[_Wait] = []
    command: list[Event] = []
    reply: list[Event] = []
    # _ends_command(command) and _line_done(reply), kept as the two grow (asked per event)
    commanded = replied = False
    for e in [*wire, None]:
        ends_exchange = e is None or e.kind is EventKind.BREAK
        if e is not None and e.origin == TOOL and e.kind is EventKind.CHAR:
            ends_exchange = bool(reply) or commanded
        if ends_exchange:
            wait = _announced_wait(command, reply)
            if wait is not None:
                waits.append(wait)
            command, reply = [], []
            commanded = replied = False
        if e is None:
            continue
        if e.kind is EventKind.BREAK:
            # a break before ttt ran out aborts (or gives up on) an M-type wait: the tool
            # chose that; a concurrent measurement runs on through it (R-4.4.7-05)
            for wait in waits:
                if not wait.concurrent:
                    wait.cut(e.start)
            continue
        if e.origin == TOOL:
            if not command:  # the first character of a command: its address
                _cut_concurrent(waits, chr(e.char7), e.start)
            command.append(e)
            commanded = _ends_command(command)
        elif commanded and not replied:
            reply.append(e)
            replied = _line_done(reply)
    return [(w.start, w.end) for w in waits]


def _cut_concurrent(waits: list[_Wait], address: str, at: float) -> None:
    """A command to a sensor ends its concurrent measurement's wait there: read early,
    or aborted (R-4.4.7.1-01), it is the tool's choice."""
    for wait in waits:
        if wait.concurrent and wait.address == address:
            wait.cut(at)


def _announced_wait(command: list[Event], reply: list[Event]) -> _Wait | None:
    if not reply:
        return None
    try:
        cmd = parse_command(decode_7e1(command))
    except CommandError:
        return None
    if not cmd.starts_measurement:
        return None
    ttt = announced_time(decode_7e1(reply), measurement_digits(cmd))
    if not ttt:
        return None
    end = reply[-1].end
    return _Wait(end, end + ttt, cmd.address, cmd.is_concurrent)


def announced_time(text: str, digits: int) -> int | None:
    """ttt of a well-formed ``atttn<CR><LF>`` (nn, nnn by ``digits``), else None."""
    body = text.removesuffix("\r\n")
    if body == text or len(body) != 4 + digits:
        return None
    shape = parse_measurement_reply(body, digits)
    return shape.ttt if shape.count is not None else None


def _ends_command(command: list[Event]) -> bool:
    """The tool's characters so far end in ``!`` (only characters are ever collected: the
    last one decides, without decoding the whole command for every event)."""
    return bool(command) and command[-1].char7 == ord("!")


def _line_done(reply: list[Event]) -> bool:
    return len(reply) >= 2 and reply[-2].char7 == ord("\r") and reply[-1].char7 == ord("\n")


def _union(spans: list[tuple[float, float]]) -> float:
    total = 0.0
    current_start = current_end = None
    for start, end in sorted(spans):
        if current_end is None or start > current_end:
            if current_end is not None:
                total += current_end - current_start
            current_start, current_end = start, end
        else:
            current_end = max(current_end, end)
    if current_end is not None:
        total += current_end - current_start
    return total
