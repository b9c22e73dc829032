"""When the recorder's events reached the served line, as far as its reads can tell.

A served line learns of the recorder's bytes and line states (RFC 2217 SET_CONTROL) from
socket reads. Events that come out of one read, or one kernel-stamped packet, arrived
together as far as the line can see: when each of them happened is known only to lie
between the previous arrival the line saw and this one. Stamping them all with the read's
time lays a command right behind the break-off that came with it, a marking of 0 ms that
no one measured (CI, stop 45: R-7.0-06 FAILed on "0.00 ms ± 5 ms" because a loaded host
woke the reader late). So the events of such a group are spread over that room, in order
(the played sensors hear a break and a marking the recorder may have made, not a 0 ms one),
and a break with an end in the room carries the room as its doubt, which the judges add to
the stamps' uncertainty: where the gap is unknowable they say INCONCLUSIVE, not FAIL.

Pure arithmetic and dispatch: the reads themselves are in :mod:`.servers`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, Protocol

from .bench import BAUD

ToolKind = Literal["bytes", "break", "rts"]


@dataclass(frozen=True)
class ToolEvent:
    """One thing the recorder did, in the order a read showed it: bytes sent at a bit rate,
    its break switched (``on``), or its transmit enable (RTS) switched (``on``)."""

    kind: ToolKind
    data: bytes = b""
    baud: int = BAUD
    on: bool = False


@dataclass(frozen=True)
class Arrival:
    """Events that reached the line together: no earlier than ``since`` (the line's previous
    arrival, which they came after), no later than ``at`` (their packet's kernel stamp, or
    the moment the read returned). ``earliest``: where the reader also saw the socket empty
    after ``since`` (:class:`~.servers.ArrivalReader`), the latest such moment, which they
    came after too; None: ``since``. ``stamped``: ``at`` is the kernel's receive stamp of
    their packet; else it is when the read returned, and even one event alone may have
    arrived anywhere in :attr:`unseen` (a late read of a packet the kernel did not stamp)."""

    events: tuple[ToolEvent, ...]
    since: float
    at: float
    earliest: float | None = None
    stamped: bool = True

    @property
    def unseen(self) -> float:
        """How long (s) before ``at`` the first of the events may have arrived: the span in
        which what came together may have been sent apart."""
        floor = self.since if self.earliest is None else max(self.since, self.earliest)
        return max(0.0, self.at - floor)


class ToolSide(Protocol):
    """What :func:`lay` drives: the recorder's side of a real-time line."""

    def tool_bytes(
        self, data: bytes, at: float | None = None, baud: int = BAUD, doubt: float = 0.0
    ) -> None: ...

    def break_on(self, at: float | None = None, doubt: float = 0.0) -> None: ...

    def break_off(self, at: float | None = None, doubt: float = 0.0) -> None: ...

    def set_rts(self, raised: bool) -> None: ...


def merged(events: Iterable[ToolEvent]) -> list[ToolEvent]:
    """Consecutive bytes at one bit rate as one event: a recorder's write goes on the wire
    back to back (the line cannot tell one write from two in one packet anyway)."""
    out: list[ToolEvent] = []
    for event in events:
        last = out[-1] if out else None
        if last is not None and event.kind == last.kind == "bytes" and event.baud == last.baud:
            out[-1] = ToolEvent("bytes", last.data + event.data, event.baud)
        else:
            out.append(event)
    return out


#: The widest step (s) between events placed in one room. The room may be long (an idle
#: recorder, then a late read); spread over all of it, a break and the marking after it
#: would reach the 87/100 ms the played sensors go to standby after, which nothing showed.
#: 25 ms holds a 12 ms break and an 8.33 ms marking, well inside those windows.
SPREAD_MAX = 25e-3


def step(room: float, count: int) -> float:
    """The step between ``count`` events placed in ``room`` s: an even share, at most
    :data:`SPREAD_MAX`."""
    return min(max(room, 0.0) / count, SPREAD_MAX) if count > 0 else 0.0


def placed(since: float, at: float, count: int) -> tuple[list[float], float]:
    """Where ``count`` timed events that arrived together go, and how far (s) each may be off.

    One event is placed at its arrival, as every stamp of the line is (the declared
    uncertainty covers how late the line may have looked). Several share the room between
    the previous arrival and this one, in order, the last at the arrival, one :func:`step`
    apart (an even share of the room); each may have been anywhere in the room, so the
    whole room is their doubt, whatever step they were placed at."""
    if count <= 1:
        return [at] * count, 0.0
    room = max(0.0, at - since)
    gap = step(room, count)
    return [at - (count - 1 - k) * gap for k in range(count)], room


def char_doubt(arrival: Arrival, timed: int, length: int) -> float:
    """How far (s) the characters of a bytes event of ``length`` bytes, one of ``timed``
    timed events of ``arrival``, may be from where they are laid: 0 for a byte alone in its
    arrival with its packet's own stamp, else :attr:`Arrival.unseen`. Bytes that came together
    are laid back to back from the arrival, but the kernel merges packets nobody read yet
    into one stamp (the later one): a recorder that sent '0', paused 20 ms, then 'M!' is
    read as '0M!' stamped at the 'M!', its first character 20 ms later and its gap 0 ms, as
    far as the stamps go. Each character may have been sent anywhere in that span."""
    return arrival.unseen if timed > 1 or length > 1 or not arrival.stamped else 0.0


def lay(line: ToolSide, arrival: Arrival) -> None:
    """Put one arrival's events on ``line`` in order, each where :func:`placed` puts it; RTS
    switches take no time of their own (they only decide whether later bytes reach the bus).
    Bytes go with the doubt :func:`char_doubt` gives them."""
    events = merged(arrival.events)
    timed = [e for e in events if e.kind != "rts"]
    times, doubt = placed(arrival.since, arrival.at, len(timed))
    if not arrival.stamped:  # one event alone, stamped as the read returned: maybe late
        doubt = max(doubt, arrival.unseen)
    slot = iter(times)
    for event in events:
        if event.kind == "rts":
            line.set_rts(event.on)
        elif event.kind == "bytes":
            chars = char_doubt(arrival, len(timed), len(event.data))
            line.tool_bytes(event.data, next(slot), event.baud, chars)
        elif event.on:
            line.break_on(next(slot), doubt)
        else:
            line.break_off(next(slot), doubt)
