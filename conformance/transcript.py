"""Timestamped bus events: the only thing links produce and the only thing judges read.

Every character on the wire is one :class:`Event` holding the 8 bits between its start and
stop bit (``wire``). For a 7E1 character bit 7 is the even-parity bit; for an 8N1 byte of a
high-volume binary packet all 8 bits are data. Keeping the raw bits lets the same record be
decoded either way (requirements.md implementation notes) and lets a parity fault show up as
evidence instead of vanishing inside a UART.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from enum import StrEnum
from itertools import islice
from math import copysign, isfinite
from operator import attrgetter
from typing import Any


class EventKind(StrEnum):
    BREAK = "break"
    CHAR = "char"
    NOTE = "note"


#: the kinds read per event, as module constants: a member read off the enum goes through
#: its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look;
#: ``decode_8n1`` looked once per character)
_CHAR, _NOTE = EventKind.CHAR, EventKind.NOTE


TOOL = "tool"  # the side this program plays (recorder in the sensor role)
DUT = "dut"  # the device under test
#: A recording that does not say who sent it (a logic-analyzer capture of the one wire, a
#: listen-only monitor): the view infers the direction from the protocol.
BUS = "bus"
#: The ``text`` of a DUT character an echoing interface returned between the echoes of the
#: tool's own characters: two talkers on the line. It is contention evidence, never the DUT's
#: reply text, and never cuts a reply (issue 18).
COLLISION = "collision"
#: The ``text`` of a recorder's break that the line held back: a recorder harness asked for it
#: while a played sensor's character was on the line, heard that character instead and asked
#: again after it. Where it ended is where the line put it, not where the recorder's own timing
#: had it (on a wire the break goes over the character), so the recorder's marking after it
#: cannot FAIL R-7.0-06 (docs/kit.md, twenty-second round).
HELD_BACK = "held back"


#: even parity of every 7-bit character (a table: every received character is checked)
_PARITY = tuple(bin(c).count("1") & 1 for c in range(0x80))
_CHR7 = tuple(chr(c) for c in range(0x80))  # a 7-bit character's text, looked up


def parity_bit(char7: int) -> int:
    """Even parity bit for a 7-bit character."""
    return _PARITY[char7 & 0x7F]


def to_wire_7e1(char7: int) -> int:
    """The 8 bits a 7E1 frame carries between start and stop bit."""
    return (char7 & 0x7F) | (parity_bit(char7) << 7)


#: each byte's 7E1 frame bits (:func:`to_wire_7e1` of its low 7 bits), for bytes.translate
_WIRE_7E1 = bytes(to_wire_7e1(c) for c in range(0x100))


def encode_7e1(text: str) -> bytes:
    """``bytes(to_wire_7e1(ord(c)) for c in text)``: a reply's or a command's frames in one
    ``bytes.translate`` (C), not a call per character (every frame of a sim run is made so)."""
    try:
        return text.encode("latin-1").translate(_WIRE_7E1)
    except UnicodeEncodeError:  # past Latin-1: its low 7 bits, as to_wire_7e1 takes them
        return bytes(_WIRE_7E1[ord(c) & 0x7F] for c in text)


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
    # of the length of a line state, where it is known apart from the stamps: better (a NUL
    # at another bit rate, timed by the UART) or worse (a NUL a monitor read: at least a
    # frame; a served line's break whose end came in one read with other events, which may
    # have ended anywhere in the room since the read before); None: as uncertain as the stamps
    duration_uncertainty: float | None = None

    @property
    def char7(self) -> int:
        return self.wire & 0x7F

    @property
    def parity_ok(self) -> bool:
        return (self.wire >> 7) == _PARITY[self.wire & 0x7F]

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


class _Unfrozen:
    """:class:`Event`'s slots, set by a plain ``__init__`` (a ``STORE_ATTR`` per slot, which
    Python 3.11 specialises), the object made an :class:`Event` by its last line: what
    :func:`full_event` makes. The frozen dataclass's own ``__init__`` sets each field through
    ``object.__setattr__`` by name, and an object made bare with each slot's setter called
    (this module's way until matrix21) was a call per field: ~1.1 us a character against
    ~0.5 us so, 10^4 to 10^5 a sim run's half and again its capture's decode (issue 22). The
    two classes have the same slots in the same order on the same base, which is exactly
    when Python lets an object's class be changed; the object is then an Event like any
    other, frozen from there on (``tests/sim/test_bus.py`` holds it to the constructor field
    by field)."""

    __slots__ = Event.__slots__

    def __init__(
        self,
        kind: EventKind,
        origin: str,
        start: float,
        end: float,
        wire: int,
        text: str,
        uncertainty: float,
        duration_uncertainty: float | None,
    ) -> None:
        self.kind = kind
        self.origin = origin
        self.start = start
        self.end = end
        self.wire = wire
        self.text = text
        self.uncertainty = uncertainty
        self.duration_uncertainty = duration_uncertainty
        self.__class__ = Event  # type: ignore[assignment]


#: ``full_event(kind, origin, start, end, wire, text, uncertainty, duration_uncertainty)``:
#: ``Event(kind, origin, start, end, wire, text, uncertainty, duration_uncertainty)`` made
#: without the frozen dataclass's ``__init__`` (:class:`_Unfrozen`), every slot set: the sim
#: bus (:func:`wire_event`, its reply and command runs), a capture's decoder and its TX merge
#: make one per character, 10^4 to 10^5 a run, 10^6 an hour's capture. The class itself, not
#: a function calling it: the call in between was a fifth of the cost.
full_event: Callable[[EventKind, str, float, float, int, str, float, float | None], Event]
full_event = _Unfrozen  # type: ignore[assignment]


def wire_event(kind: EventKind, origin: str, start: float, end: float, wire: int = 0) -> Event:
    """``Event(kind, origin, start, end, wire=wire)``, every other field at its default, made
    by :func:`full_event` (no frozen ``__init__``): the sim bus makes one per character, 10^4
    to 10^5 a run (``tests/sim/test_bus.py`` holds it to the constructor field by field)."""
    return full_event(kind, origin, start, end, wire, "", 0.0, None)


def in_start_order(events: Iterable[Event]) -> list[Event]:
    """``events`` but notes, sorted stably by start: the list itself where it is one so
    already (a capture's, a link's: one pass, no copy; a caller only reads it), else a sorted
    copy. The copy and its sort's keys were two lists of every event (issue 22: ~6 MB each
    time an hour's busy capture was sorted so, by the view's cut and by the bus time). A
    list is taken as in order exactly when the sort would leave it so (each start compared
    with the one before as the sort compares them), so it is the list the sort gives."""
    note = _NOTE
    if isinstance(events, list):
        last = None
        for e in events:
            if e.kind is note or (last is not None and e.start < last):
                break
            last = e.start
        else:
            return events
    wire = [e for e in events if e.kind is not note]
    wire.sort(key=_START_OF)
    return wire


_START_OF = attrgetter("start")


def decode_7e1(events: Iterable[Event]) -> str:
    """Text of 7E1 characters (parity stripped: a frame's parity is ``Event.parity_ok``)."""
    char = _CHAR
    return "".join([_CHR7[e.wire & 0x7F] for e in events if e.kind is char])


#: the wire bits of every 7E1 character with good parity, as the bytes ``bytes.translate``
#: deletes from a run's wire bytes (what is left: its parity errors, ``Event.parity_ok``)
GOOD_PARITY = bytes(sorted(to_wire_7e1(c) for c in range(0x80)))
#: a wire byte's seven character bits, as a ``bytes.translate`` table
SEVEN_BITS = bytes(w & 0x7F for w in range(0x100))


def wire_bytes(events: list[Event]) -> bytes | None:
    """Each event's ``wire`` as one byte, or None where some wire is no byte (a made-up
    event): a run's characters read in one C pass (:data:`SEVEN_BITS`,
    :data:`GOOD_PARITY`) rather than an ``Event.char7``/``parity_ok`` call apiece."""
    try:
        return bytes([e.wire for e in events])
    except (TypeError, ValueError):
        return None


def text7(events: list[Event]) -> str:
    """``"".join(chr(e.char7) for e in events)``, of every event whatever its kind: a
    run's characters as text, parity stripped, in one C pass where every wire is a byte."""
    wires = wire_bytes(events)
    if wires is None:
        return "".join([chr(e.char7) for e in events])
    return wires.translate(SEVEN_BITS).decode("ascii")


def decode_8n1(events: Iterable[Event]) -> bytes:
    return bytes(e.wire for e in events if e.kind is _CHAR)


def text_end(events: list[Event], text: str) -> float | None:
    """End of the first run of characters spelling ``text`` with good parity (e.g. a service
    request ``a<CR><LF>``), or None."""
    n = len(text)
    for i in range(n - 1, len(events)):
        tail = events[i - n + 1 : i + 1]
        if decode_7e1(tail) == text and all(e.parity_ok for e in tail):
            return tail[-1].end
    return None


class _Escapes(dict):
    """How :func:`escape` shows each character (str.translate: one pass in C), down to the
    ones past Latin-1 it makes up as asked."""

    def __missing__(self, code: int) -> str:
        return f"<0x{code:02X}>"


_NAMES = {"\r": "<CR>", "\n": "<LF>", "\x02": "<STX>", "\x03": "<ETX>"}
_ESCAPES = _Escapes(
    {c: _NAMES.get(chr(c), chr(c) if 0x20 <= c <= 0x7E else f"<0x{c:02X}>") for c in range(0x100)}
)


def escape(data: str | bytes) -> str:
    """Printable rendering of wire text: ``<CR><LF>``, ``<0x02>``... for evidence lines."""
    if isinstance(data, bytes):
        data = data.decode("latin-1")
    if data.isascii() and data.isprintable():
        return data
    return data.translate(_ESCAPES)


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

    def write_jsonl(self, path: str) -> bool:
        """One :func:`json_line` per event (:func:`write_jsonl`)."""
        return write_jsonl(path, self.events)


def write_jsonl(path: str, events: Iterable[Event]) -> bool:
    """One :func:`json_line` per event of ``events``, read once in order (a list, or a
    recording's events streamed from its first: issue 22, a passive run's transcript file
    written with no list of the recording's events). Returns whether every event had
    :func:`plain_fields`, which each line asks anyway (a caller keeping what it wrote as its
    own reading needs to know, and asking again cost a second pass over 10^5)."""
    plain = True
    shown = _LastEnd()
    parts: dict[tuple[object, ...], tuple[str, str]] = {}  # _line_parts by the fields
    them = iter(events)
    with open(path, "w", encoding="utf-8") as fh:
        # written a block of lines at a time: an hour's capture is 43 MB of lines, which
        # formatted whole before writing were the peak of a passive judgement's memory
        while block := list(islice(them, WRITE_BLOCK)):
            lines: list[str] = []
            add = lines.append
            for e in block:
                if not plain_fields(e):
                    plain = False
                    add(json.dumps(e.to_json()) + "\n")
                    continue
                u, du = e.uncertainty, e.duration_uncertainty
                key = (e.kind, e.origin, e.wire, e.text, u, du)
                found = parts.get(key)
                # a negative zero is equal to 0.0 as a key, but written apart
                signed = (not u and copysign(1.0, u) < 0) or (
                    du is not None and not du and copysign(1.0, du) < 0
                )
                if found is None or signed or not isfinite(e.start + e.end):
                    add(_plain_line(e, shown))
                    if found is None and not signed and isfinite(u + (du or 0.0)):
                        parts[key] = _line_parts(e)
                    continue
                start, end = shown.times(e.start, e.end)
                head, tail = found
                add(f'{head}{start}, "end": {end}{tail}')
            fh.writelines(lines)
    return plain


#: lines of a transcript formatted before they are written (bounded memory, few writes)
WRITE_BLOCK = 4096
_quote = json.encoder.encode_basestring_ascii  # how json.dumps writes a str (ensure_ascii)


def plain_fields(e: Event) -> bool:
    """Whether every field of ``e`` has exactly the plain type a transcript line reads back
    as (floats for the times, an int wire byte, str texts): what :func:`json_line` writes
    directly, and what lets a transcript just written stand for its own reading."""
    du = e.duration_uncertainty
    return (
        type(e.kind) is EventKind
        and type(e.origin) is str
        and type(e.text) is str
        and type(e.wire) is int
        and type(e.start) is float
        and type(e.end) is float
        and type(e.uncertainty) is float
        and (du is None or type(du) is float)
    )


def json_line(event: Event) -> str:
    """``json.dumps(event.to_json()) + "\n"``: a transcript's line. Written directly when
    every field has the plain type whose JSON is its repr (json.dumps builds an encoder per
    call, most of the cost of writing a run's 10^5 events), else by json.dumps."""
    if plain_fields(event):
        return _plain_line(event)
    return json.dumps(event.to_json()) + "\n"


def _line_parts(e: Event) -> tuple[str, str]:
    """What :func:`_plain_line` writes of ``e`` before its start and after its end: the
    same for every event with its kind, origin, wire byte, text and uncertainties (a run's
    characters share a few hundred such), so :meth:`Transcript.write_jsonl` keeps them and
    formats them once per run rather than per line (kept only where no uncertainty is a
    negative zero, which is equal to 0.0 as a key but written apart)."""
    du = e.duration_uncertainty
    tail = "}\n" if du is None else f', "duration_uncertainty": {du!r}}}\n'
    return (
        f'{{"kind": "{e.kind}", "origin": {_quote(e.origin)}, "start": ',
        f', "wire": {e.wire!r}, "text": {_quote(e.text)}, "uncertainty": {e.uncertainty!r}{tail}',
    )


class _LastEnd:
    """The previous line's end time and how it was written. A character on the bus starts
    where the one before it ended, so a run's transcript writes about 40% of its times twice,
    and a float's shortest repr (``_Py_dg_dtoa``) was 5% of a whole ``--port sim`` process."""

    __slots__ = ("end", "text")

    def __init__(self) -> None:
        self.end: float | None = None
        self.text = ""

    def times(self, start: float, end: float) -> tuple[str, str]:
        """A line's start and end as written: the start as the line before's end text when
        equal (never a zero: 0.0 and -0.0 are equal but written apart); this end kept."""
        shown = self.text if start == self.end and start != 0.0 else repr(start)
        self.end, self.text = end, repr(end)
        return shown, self.text


def _plain_line(e: Event, shown: _LastEnd | None = None) -> str:
    """:func:`json_line` of an event with :func:`plain_fields` (a non-finite time still goes
    through json.dumps, which spells it its own way). ``{e.kind}`` is ``str(e.kind)``, the
    value: a StrEnum formats as its str. ``shown``: the line before's end, whose text stands
    for a start equal to it (never a zero: 0.0 and -0.0 are equal but written apart)."""
    if not math.isfinite(e.start + e.end + e.uncertainty + (e.duration_uncertainty or 0.0)):
        return json.dumps(e.to_json()) + "\n"
    head, tail = _line_parts(e)
    start, end = (repr(e.start), repr(e.end)) if shown is None else shown.times(e.start, e.end)
    return f'{head}{start}, "end": {end}{tail}'
