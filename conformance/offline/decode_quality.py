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
from collections.abc import Iterable, Sequence
from itertools import islice
from math import copysign
from operator import le
from typing import Any

from ..capture.uart import character_problems
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
        self._read(decoded.baud_error_pct, events)  # one per character, in events' order

    @classmethod
    def of_rates(cls, rates: Sequence[float], events: list[Event]) -> CharRates:
        """The errors ``rates`` of ``events``' characters, one for one in their order: a
        window's share of the decode's (issue 22's windowed judge reads a window at a time)."""
        found = cls.__new__(cls)
        found._read(rates, events)
        return found

    def _read(self, rates: Sequence[float], events: list[Event]) -> None:
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


def problems_by_character(decoded: Any) -> dict[tuple[float, int], Any]:
    """The decode's problem items of characters (framing or parity error, a glitch), by the
    start and byte of their character, not its identity: a decode that widened its stamps
    (the glitch filter beside an edge) holds new events, its problems the ones it first
    read."""
    return {(p.event.start, p.event.wire): p for p in character_problems(decoded.problems)}


class RateTally:
    """Measured bit-rate errors, for their min, median and max as ``min``,
    ``statistics.median`` and ``max`` of the list of them give those (the very floats): each
    distinct value and how often it came, in memory that grows with the distinct values,
    not the characters (a decode's errors are float32 ratios of whole sample counts: a few
    hundred distinct values in an hour's busy capture, issue 22). Past :data:`DISTINCT`
    values, or at a ``-0.0`` (equal to ``0.0``, printed apart: which one a median or a min
    gives depends on their order), the values are listed in order instead, as they were."""

    #: distinct values a tally keeps before it lists them
    DISTINCT = 4096

    def __init__(self) -> None:
        self.counts: dict[float, int] = {}
        self.listed: array | None = None  # the values in order, once a tally will not do

    def extend(self, values: list[float]) -> None:
        """More values (no NaN)."""
        if self.listed is None:
            counts = self.counts
            for i, v in enumerate(values):
                if v == 0.0 and copysign(1.0, v) < 0:
                    self._list()
                    values = values[i:]
                    break
                counts[v] = counts.get(v, 0) + 1
            else:
                if len(counts) > self.DISTINCT:
                    self._list()
                return
        self.listed.extend(values)  # type: ignore[union-attr]

    def _list(self) -> None:
        """From here on the values in order: those so far sorted (each 0.0 then came
        before any ``-0.0``, so the order among equal values a sort keeps is theirs)."""
        self.listed = array("d", [v for v in sorted(self.counts) for _ in range(self.counts[v])])
        self.counts = {}

    def __bool__(self) -> bool:
        return bool(self.counts) or bool(self.listed)

    def summary(self) -> tuple[float, float, float]:
        """(min, median, max) of the values (there are some)."""
        if self.listed is not None:
            values = self.listed
            return min(values), statistics.median(values), max(values)
        ordered = sorted(self.counts)
        n = sum(self.counts.values())
        below, low_mid, mid = 0, None, None
        for v in ordered:  # the values at sorted positions (n - 1) // 2 and n // 2
            below += self.counts[v]
            if low_mid is None and below > (n - 1) // 2:
                low_mid = v
            if below > n // 2:
                mid = v
                break
        assert low_mid is not None and mid is not None
        median = mid if n % 2 else (low_mid + mid) / 2
        return ordered[0], median, ordered[-1]


class Quality:
    """One sensor's decode figures gathered a part of the recording at a time (issue 22's
    windowed judge: each window's characters of the sensor :meth:`add`-ed as they come), the
    note :func:`decode_quality` gives all of them at once. It keeps counts and the measured
    bit-rate errors as a :class:`RateTally` (it kept 8 bytes a character, for the median:
    an hour's busy capture held 5.5 MB of them while its bus pass ran), never the
    characters."""

    def __init__(self) -> None:
        self.chars = self.parity = self.framing = self.glitched = 0
        self.measured = RateTally()

    def add(
        self, chars: list[Event], error: CharRates, broken: dict[tuple[float, int], Any]
    ) -> None:
        """``chars`` (the sensor's, in order), their bit-rate errors looked up in ``error``
        and their problems in ``broken`` (:func:`problems_by_character`)."""
        self.chars += len(chars)
        self.measured.extend([v for v in map(error.get, chars) if v is not None and v == v])
        self.parity += sum(1 for c in chars if not c.parity_ok)
        flagged = [broken[(c.start, c.wire)] for c in chars if (c.start, c.wire) in broken]
        self.framing += sum(1 for d in flagged if d.framing_error)
        self.glitched += sum(1 for d in flagged if d.glitches)

    def note(self, baud: float, who: str) -> str | None:
        """The note on everything added (None: no character)."""
        if not self.chars:
            return None
        rate, measured = "bit rate not measurable", self.measured
        if measured:
            low, mid, high = measured.summary()
            rate = f"bit rate {low:+.2f}..{high:+.2f} % off {baud:g} baud (median {mid:+.2f} %)"
        return (
            f"decode quality of {who}: {self.chars} character(s), {rate}; {self.parity} with a "
            f"parity error, {self.framing} with a framing error, {self.glitched} with a "
            "glitch inside"
        )


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
    quality = Quality()
    error = rate_of(decoded, events) if rates is None else rates
    quality.add(chars, error, problems_by_character(decoded))
    return quality.note(decoded.baud, who)
