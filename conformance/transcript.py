"""Timestamped bus events: the only thing links produce and the only thing judges read.

Every character on the wire is one :class:`Event` holding the 8 bits between its start and
stop bit (``wire``). For a 7E1 character bit 7 is the even-parity bit; for an 8N1 byte of a
high-volume binary packet all 8 bits are data. Keeping the raw bits lets the same record be
decoded either way (requirements.md implementation notes) and lets a parity fault show up as
evidence instead of vanishing inside a UART.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any


class EventKind(StrEnum):
    BREAK = "break"
    CHAR = "char"
    NOTE = "note"


TOOL = "tool"  # the side this program plays (recorder in the sensor role)
DUT = "dut"  # the device under test
#: A recording that does not say who sent it (a logic-analyzer capture of the one wire, a
#: listen-only monitor): the view infers the direction from the protocol.
BUS = "bus"
#: The ``text`` of a DUT character an echoing interface returned between the echoes of the
#: tool's own characters: two talkers on the line. It is contention evidence, never the DUT's
#: reply text, and never cuts a reply (issue 18).
COLLISION = "collision"


def parity_bit(char7: int) -> int:
    """Even parity bit for a 7-bit character."""
    return bin(char7 & 0x7F).count("1") & 1


def to_wire_7e1(char7: int) -> int:
    """The 8 bits a 7E1 frame carries between start and stop bit."""
    return (char7 & 0x7F) | (parity_bit(char7) << 7)


@dataclass(frozen=True, slots=True)
class Event:
    """One thing that happened on the bus, stamped in seconds on the link's clock.

    ``start``/``end`` of a character are its start-bit leading edge and stop-bit end; of a
    break, the spacing's start and end. ``uncertainty`` is the link's stamp uncertainty.
    """

    kind: EventKind
    origin: str
    start: float
    end: float
    wire: int = 0
    text: str = ""
    uncertainty: float = 0.0
    # of the length of a line state the UART timed (a NUL at another bit rate), when that is
    # far better known than its position; None: the length is as uncertain as the stamps
    duration_uncertainty: float | None = None

    @property
    def char7(self) -> int:
        return self.wire & 0x7F

    @property
    def parity_ok(self) -> bool:
        return (self.wire >> 7) == parity_bit(self.wire)

    @property
    def duration(self) -> float:
        return self.end - self.start

    def to_json(self) -> dict[str, Any]:
        return {
            "kind": str(self.kind),
            "origin": self.origin,
            "start": self.start,
            "end": self.end,
            "wire": self.wire,
            "text": self.text,
            "uncertainty": self.uncertainty,
        } | (
            {}
            if self.duration_uncertainty is None
            else {"duration_uncertainty": self.duration_uncertainty}
        )

    @property
    def length_uncertainty(self) -> float:
        """How well the length ``end - start`` is known (s)."""
        if self.duration_uncertainty is not None:
            return self.duration_uncertainty
        return self.uncertainty


def decode_7e1(events: Iterable[Event]) -> str:
    """Text of 7E1 characters (parity stripped: a frame's parity is ``Event.parity_ok``)."""
    return "".join(chr(e.char7) for e in events if e.kind is EventKind.CHAR)


def decode_8n1(events: Iterable[Event]) -> bytes:
    return bytes(e.wire for e in events if e.kind is EventKind.CHAR)


def text_end(events: list[Event], text: str) -> float | None:
    """End of the first run of characters spelling ``text`` with good parity (e.g. a service
    request ``a<CR><LF>``), or None."""
    n = len(text)
    for i in range(n - 1, len(events)):
        tail = events[i - n + 1 : i + 1]
        if decode_7e1(tail) == text and all(e.parity_ok for e in tail):
            return tail[-1].end
    return None


def escape(data: str | bytes) -> str:
    """Printable rendering of wire text: ``<CR><LF>``, ``<0x02>``... for evidence lines."""
    if isinstance(data, bytes):
        data = data.decode("latin-1")
    names = {"\r": "<CR>", "\n": "<LF>", "\x02": "<STX>", "\x03": "<ETX>"}
    return "".join(names.get(c, c if 0x20 <= ord(c) <= 0x7E else f"<0x{ord(c):02X}>") for c in data)


@dataclass
class Transcript:
    """The ordered events a link recorded. Append-only; slices of it are judged."""

    events: list[Event] = field(default_factory=list)

    def add(self, event: Event) -> Event:
        self.events.append(event)
        return event

    def note(self, time: float, text: str) -> Event:
        return self.add(Event(EventKind.NOTE, TOOL, time, time, text=text))

    def __iter__(self) -> Iterator[Event]:
        return iter(self.events)

    def __len__(self) -> int:
        return len(self.events)

    def since(self, index: int) -> list[Event]:
        return self.events[index:]

    def write_jsonl(self, path: str) -> None:
        with open(path, "w", encoding="utf-8") as fh:
            line = _JsonLines().line
            fh.writelines(line(event) for event in self.events)


class _JsonLines:
    """``json.dumps(event.to_json()) + "\\n"``, written without building the dict and
    encoding it through the json module for each event (a run holds tens of thousands):
    the same text, byte for byte; an event with anything but finite floats for its times
    takes the json module's way."""

    def __init__(self) -> None:
        self._heads: dict[tuple[EventKind, str], str] = {}  # kinds and origins repeat
        self._texts: dict[str, str] = {}  # and so do texts (nearly always "")

    def line(self, e: Event) -> str:
        start, end, u, du = e.start, e.end, e.uncertainty, e.duration_uncertainty
        if not (
            type(start) is float
            and type(end) is float
            and type(u) is float
            and start - start == end - end == u - u == 0.0  # finite: json writes the repr
            and (du is None or (type(du) is float and du - du == 0.0))
            and type(e.wire) is int
            and type(e.origin) is str
            and type(e.text) is str
            and isinstance(e.kind, EventKind)
        ):
            return json.dumps(e.to_json()) + "\n"
        head = self._heads.get((e.kind, e.origin))
        if head is None:
            head = self._heads[(e.kind, e.origin)] = (
                f'{{"kind": {json.dumps(str(e.kind))}, "origin": {json.dumps(e.origin)}, '
            )
        text = self._texts.get(e.text)
        if text is None:
            text = self._texts[e.text] = json.dumps(e.text)
        tail = "}\n" if du is None else f', "duration_uncertainty": {du!r}}}\n'
        return (
            f'{head}"start": {start!r}, "end": {end!r}, "wire": {e.wire!r}, "text": {text}, '
            f'"uncertainty": {u!r}{tail}'
        )
