"""How well one sensor's characters decoded from a capture: the figures a reader weighs the
sensor's verdicts by (issue 23, item 3).

A capture of a field bus holds several sensors, each with its own oscillator and cable: one
may run 3 % fast while the others are exact, or be the one whose frames break. The decode's
figures for the whole capture hide that, so each sensor's report gives its own: how many of
its characters decoded, their bit-rate error (min, median, max), and how many had a parity or
framing error or a glitch inside. Pure: it reads the decode and the sensor's exchanges.
"""

from __future__ import annotations

import statistics
from array import array
from bisect import bisect_left
from collections.abc import Iterable
from itertools import islice
from operator import le
from typing import Any

from ..tool_recorder.records import Exchange
from ..transcript import Event, EventKind


def sensor_characters(exchanges: Iterable[Exchange]) -> list[Event]:
    """Every character the sensor sent in ``exchanges``' replies, every attempt's."""
    return [e for ex in exchanges for a in ex.attempts for e in a.reply_events]


class CharRates:
    """Each character's bit-rate error, looked up by the character: made once for all the
    sensors of a bus (:func:`decode_quality`'s ``rates``) rather than once each, each pass
    over the whole capture. The decode gives the errors in the order of its characters; a
    character is found among them by its start (a bisection of their starts, kept as an
    array, then its identity among the characters with that start), where a map from every
    character to its error was a transient of 90 bytes a character (an hour's capture: 30 MB
    at the peak of its judging). Characters out of time order (never seen from a decode)
    are mapped by identity, as they all were."""

    def __init__(self, decoded: Any, events: list[Event]) -> None:
        rates = decoded.baud_error_pct  # one per character, in the order of the events
        chars = [e for e in events if e.kind is EventKind.CHAR]
        # (a list that does not match the characters one for one tells no character's rate)
        self._rates = rates if len(rates) == len(chars) else None
        self._chars = chars
        starts = array("d", [e.start for e in chars])
        ordered = all(map(le, starts, islice(starts, 1, None)))
        self._starts = starts if ordered else None
        self._by_id: dict[int, float] = {}
        if self._rates is not None and not ordered:
            self._by_id = dict(zip(map(id, chars), self._rates, strict=True))

    def get(self, c: Event) -> float | None:
        """``c``'s bit-rate error in %, None if it is not one of the decode's characters."""
        if self._rates is None:
            return None
        if self._starts is None:
            return self._by_id.get(id(c))
        starts, at = self._starts, c.start
        i = bisect_left(starts, at)
        while i < len(starts) and starts[i] == at:
            if self._chars[i] is c:
                return self._rates[i]
            i += 1
        return None


def rate_of(decoded: Any, events: list[Event]) -> CharRates:
    """The bit-rate error of every character of ``events`` (:class:`CharRates`)."""
    return CharRates(decoded, events)


def decode_quality(
    decoded: Any,
    events: list[Event],
    chars: list[Event],
    who: str,
    rates: CharRates | None = None,
) -> str | None:
    """One note on ``chars`` (the sensor's characters among ``events``, the capture's decoded
    events in order) as ``decoded`` (a :class:`~conformance.capture.decode.CaptureDecode`)
    read them; None when the sensor sent none. ``rates``: :func:`rate_of` ``events``, when
    the caller made it already."""
    if not chars:
        return None
    error = rate_of(decoded, events) if rates is None else rates
    # by start and byte, not identity: a decode that widened its stamps (the glitch filter
    # beside an edge) holds new events, its problems the ones it first read
    broken = {
        (p.event.start, p.event.wire): p
        for p in decoded.problems
        if p.kind == "char" and p.event is not None
    }
    measured = [v for v in map(error.get, chars) if v is not None and v == v]
    parity = sum(1 for c in chars if not c.parity_ok)
    flagged = [broken[(c.start, c.wire)] for c in chars if (c.start, c.wire) in broken]
    framing = sum(1 for d in flagged if d.framing_error)
    glitched = sum(1 for d in flagged if d.glitches)
    rate = "bit rate not measurable"
    if measured:
        low, mid, high = min(measured), statistics.median(measured), max(measured)
        rate = f"bit rate {low:+.2f}..{high:+.2f} % off {decoded.baud:g} baud (median {mid:+.2f} %)"
    return (
        f"decode quality of {who}: {len(chars)} character(s), {rate}; {parity} with a parity "
        f"error, {framing} with a framing error, {glitched} with a glitch inside"
    )
