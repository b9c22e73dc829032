"""Wire events typed by hand for the judges' and view's tests: characters back to back from
a start, and a recorder's break, marking and command (many tests build a few hundred
milliseconds of bus this way to place one character exactly where a rule is decided)."""

from __future__ import annotations

from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import BUS, Event, EventKind, to_wire_7e1


def chars(
    origin: str, text: str, start: float, *, parity: bool = True, uncertainty: float = 0.0
) -> list[Event]:
    """``text``'s characters from ``origin``, back to back from ``start`` (``parity``
    False: every one with its parity bit wrong)."""
    flip = 0 if parity else 0x80
    return [
        Event(EventKind.CHAR, origin, start + k * CHAR_TIME, start + (k + 1) * CHAR_TIME,
              wire=to_wire_7e1(ord(c)) ^ flip, uncertainty=uncertainty)
        for k, c in enumerate(text)
    ]  # fmt: skip


def sent(events: list[Event], t: float, text: str) -> float:
    """``text``'s characters on the one wire (a capture's ``BUS``) from ``t`` on, appended to
    ``events``; gives where they end."""
    events += chars(BUS, text, t)
    return t + len(text) * CHAR_TIME


def woken(events: list[Event], t: float, command: str) -> float:
    """A 12.5 ms break at ``t``, 9 ms of marking and ``command`` on the one wire, appended to
    ``events``; gives 9 ms after the command ends."""
    events.append(Event(EventKind.BREAK, BUS, t, t + 0.0125))
    return sent(events, t + 0.0125 + 0.009, command) + 0.009
