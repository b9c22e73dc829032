"""A decoded channel's events kept as columns, each :class:`~conformance.transcript.Event` made
only when something asks for the events (issue 22, the thirteenth matrix round).

A fault-matrix row's capture decodes to ~2*10^4 characters, and its replay reads only their
starts, ends, bytes and sides (:meth:`conformance.replay.sensor.RecordedSensor.of_columns`):
making an event object per character was a third of the row's decode. Every character the
bulk decoder certifies is the same event but for those four fields (kind CHAR, no text, the
capture's uncertainty, no duration uncertainty), so it is four list entries here; the few
other items (breaks, spacing pulses, frames read one at a time) keep the event the decoder
made, by position. :meth:`WireColumns.events` gives exactly the list the decoder would have
made (``tests/capture/test_wire_columns.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from itertools import compress, islice
from operator import le

from ..transcript import Event, EventKind, full_event, plain_fields


@dataclass
class WireColumns:
    """Events in decode order as columns: ``start``, ``end``, ``wire`` and ``origin`` of
    every one, and the event itself of those that are not a certified character
    (``made``, by position). A certified character's event is
    ``full_event(CHAR, origin, start, end, wire, "", uncertainty, None)``."""

    uncertainty: float
    start: list[float] = field(default_factory=list)
    end: list[float] = field(default_factory=list)
    wire: list[int] = field(default_factory=list)
    origin: list[str] = field(default_factory=list)
    made: dict[int, Event] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.start)

    def appenders(self) -> tuple[Callable, Callable, Callable, Callable]:
        """The appends of a certified character's four columns (start, end, wire,
        origin), for a decoder's loop to bind once."""
        return self.start.append, self.end.append, self.wire.append, self.origin.append

    def add_made(self, event: Event) -> None:
        """An event the decoder made itself (a break, a pulse, a frame read alone)."""
        self.made[len(self.start)] = event
        self.start.append(event.start)
        self.end.append(event.end)
        self.wire.append(event.wire)
        self.origin.append(event.origin)

    def event(self, i: int) -> Event:
        """The ``i``-th event."""
        made = self.made.get(i)
        if made is not None:
            return made
        return full_event(
            EventKind.CHAR, self.origin[i], self.start[i], self.end[i], self.wire[i], "",
            self.uncertainty, None,
        )  # fmt: skip

    def events(self) -> list[Event]:
        """Every event, as the decoder would have listed them."""
        return self._made(self.start, self.end, self.wire, self.origin, range(len(self.start)))

    def events_at(self, keep: list[bool]) -> list[Event]:
        """The events where ``keep`` is true, in order."""
        return self._made(
            *(compress(c, keep) for c in (self.start, self.end, self.wire, self.origin)),
            compress(range(len(self.start)), keep),
        )

    def _made(
        self,
        start: Iterable[float],
        end: Iterable[float],
        wire: Iterable[int],
        origin: Iterable[str],
        at: Iterable[int],
    ) -> list[Event]:
        """The events of these columns' entries (at these positions): a certified
        character's made in one comprehension, the decoder's own put in its place."""
        unc, char, made, event = self.uncertainty, EventKind.CHAR, self.made, full_event
        if not made:
            return [
                event(char, o, s, e, w, "", unc, None)
                for s, e, w, o in zip(start, end, wire, origin, strict=True)
            ]
        return [
            made[i] if i in made else event(char, o, s, e, w, "", unc, None)
            for s, e, w, o, i in zip(start, end, wire, origin, at, strict=True)
        ]

    def kinds(self) -> list[EventKind]:
        """Every event's kind."""
        made, char = self.made, EventKind.CHAR
        kinds = [char] * len(self.start)
        for i, e in made.items():
            kinds[i] = e.kind
        return kinds

    def uncertainties(self) -> list[float]:
        """Every event's uncertainty."""
        out = [self.uncertainty] * len(self.start)
        for i, e in self.made.items():
            out[i] = e.uncertainty
        return out

    def plain(self) -> bool:
        """Whether every event has the plain field types a transcript line reads back as
        (:func:`~conformance.transcript.plain_fields`), without making the events."""
        return (
            set(map(type, self.start)) <= {float}
            and set(map(type, self.end)) <= {float}
            and set(map(type, self.wire)) <= {int}
            and set(map(type, self.origin)) <= {str}
            and type(self.uncertainty) is float
            and all(map(plain_fields, self.made.values()))
        )

    def in_start_order(self) -> bool:
        """Whether the starts never decrease (a stable sort by start leaves the order): each
        start ``<=`` the next, compared in C (``operator.le`` mapped over the column and its
        tail, not a generator step a pair: 2x faster on a row's ~2*10^4); a NaN is in no
        order, as with ``<=``."""
        s = self.start
        return all(map(le, s, islice(s, 1, None)))
