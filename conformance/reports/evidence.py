"""Where on the wire a finding rests: a reference from a FAIL, WARN or INCONCLUSIVE finding to
the transcript events of the exchange behind it.

A report once showed, beside an R-4.2-03 FAIL on ``0D3!``, the ``?!`` exchange another rule of
the case had attached, and sent the reader to transcript.jsonl for the rest. So the exchange is
looked up per finding, from what the finding itself says, in this order of trust:

1. the commands its evidence lines (then its detail) name, e.g. ``reply to 0D3!``; a line that
   is a sequence of commands, ``0MC! 0D0!`` (a measurement and the data read that judged it),
   names the exchanges from the first through the next of the last that follows it, so the
   reply that carried the fault (the D reply's CRC) is inside the reference, not after it;
2. among those (or, if it names none, among every exchange searched), the one holding an
   interval equal to the value a timing finding measured;
3. otherwise the case's own traffic as a whole (an INCONCLUSIVE that no exchange exercised
   rests on what the case did, all of it).

Exchanges are searched first in the events the case attached, then in the traffic made while
the case ran, then in the run's traffic up to the case's end (a case may judge a reply the
session cached from an earlier case). The reference gives the events' positions in the
transcript (0-based: the lines of transcript.jsonl) and their times on the link clock, so a
script can cut the same exchange out of transcript.jsonl the report draws.
"""

from __future__ import annotations

import math
import re
from bisect import bisect_left
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from itertools import islice
from operator import attrgetter
from typing import TYPE_CHECKING, Any

from ..judges.cite import STAMP
from ..results import CaseRecord
from ..transcript import Event, EventKind, Transcript
from ..verdicts import Finding, Verdict
from ..view.runs import LazyCut, Segment, segments, whole_cut
from ..view.segments import memo

if TYPE_CHECKING:
    from ..links.base import BusEnd

#: the verdicts a reader must be able to check against the wire
NEEDS_EVIDENCE = (Verdict.FAIL, Verdict.WARN, Verdict.INCONCLUSIVE)
MEASURE_MATCH_MS = 0.05  # a measured value matches an interval this close (rounding)
LATER_SHOWN = 40  # characters after a reply kept in an exchange (what the line did next)
COMMAND = re.compile(r"[0-9A-Za-z?]\w*!")  # text naming a command, e.g. "reply to 0D3!"
#: a line (or a detail's part before ':') that is a sequence of commands, "0MC! 0D0!"
CHAIN = re.compile(r"^\s*((?:[0-9A-Za-z?]\w*!\s+)+[0-9A-Za-z?]\w*!)\s*(?::|$)")


@dataclass(frozen=True)
class WireRef:
    """Transcript events ``first..last`` (inclusive), from ``start_s`` to ``end_s``."""

    first: int
    last: int
    start_s: float
    end_s: float
    exchange: str | None  # the command of the exchange; None: the case's traffic as a whole
    how: str  # "command", "measured", "command and measured" or "case"

    def to_json(self) -> dict[str, Any]:
        return {
            "transcript_events": [self.first, self.last],
            "start_s": round(self.start_s, 6),
            "end_s": round(self.end_s, 6),
            "exchange": self.exchange,
            "located_by": self.how,
        }


def _named(command: str, text: str) -> bool:
    """Whether ``text`` names ``command`` as a whole (``0M!`` is not in ``10M!``)."""
    at = text.find(command)
    while at >= 0:
        if at == 0 or not text[at - 1].isalnum():
            return True
        at = text.find(command, at + 1)
    return False


def _chain(line: str, segs: Sequence[Segment]) -> list[Segment] | None:
    """The exchanges a line such as ``0MC! 0D0!`` names, in that order on the wire: the
    first occurrence of the first command, then each next command after it (None: the
    line is no such sequence, or the wire does not hold it)."""
    match = CHAIN.match(line)
    if not match:
        return None
    chain: list[Segment] = []
    at = 0
    texts = _texts(segs)
    for command in match.group(1).split():
        found = next((i for i in range(at, len(segs)) if texts[i] == command), None)
        if found is None:
            return None
        chain.append(segs[found])
        at = found + 1
    return chain


def _with_chars(transmissions: Sequence[Any]) -> Sequence[Any]:
    """The transmissions with characters: read window by window where they are a
    recording's windows' (:class:`~..view.windows.WindowedTransmissions`), not listed."""
    with_chars = getattr(transmissions, "with_chars", None)
    if with_chars is not None:
        return with_chars()
    return [t for t in transmissions if t.chars]


def _texts(segs: Sequence[Segment]) -> list[str]:
    """The segments' texts, read without making the segments of a :class:`LazyCut`."""
    return segs.texts() if isinstance(segs, LazyCut) else [s.text for s in segs]


def _named_in(segs: Sequence[Segment], lines: list[str]) -> list[Segment]:
    """The segments whose command one of ``lines`` names, each once: those the first line
    names in wire order, then the next line's not yet taken, and so on."""
    texts = _texts(segs)
    taken: list[int] = []
    for line in lines:
        seen = set(taken)
        taken += [i for i, x in enumerate(texts) if x and _named(x, line) and i not in seen]
    return [segs[i] for i in taken]


def _nearest_measured(segs: Sequence[Segment], target: float) -> tuple[float, Segment] | None:
    """The first segment (wire order) holding an interval nearest ``target`` ms, with how
    near: what scoring every segment by its nearest interval and taking the first of the
    least finds. A :class:`LazyCut` (a whole recording's) answers from an index of its
    intervals made once (:class:`~.timing_diagram.MeasureIndex`), not by making each of its
    segments for each finding; one with a NaN interval, whose order the index does not
    keep as the scan does, is scanned."""
    if isinstance(segs, LazyCut):
        index, has_nan = memo(segs, "_measure_index", len(segs), lambda: _index(segs))
        if not has_nan and target == target:  # a NaN target: scanned, as before
            found = index.nearest(target)
            if found is None:
                return None
            best = segs[found]
            return min(abs(m - target) for m in _measures(best)), best
    scored = [(min(abs(m - target) for m in _measures(s)), s) for s in segs if _measures(s)]
    return min(scored, key=lambda p: p[0]) if scored else None


def _index(segs: LazyCut) -> tuple[Any, bool]:
    """:class:`~.timing_diagram.MeasureIndex` of ``segs`` and whether an interval is NaN."""
    from .timing_diagram import MeasureIndex

    index = MeasureIndex(segs)
    return index, any(v != v for v in index.values)


def _distance(seg: Segment, t: float) -> float:
    """How far (s) the instant ``t`` lies outside the exchange ``seg`` (0: within it)."""
    events = _exchange_events(seg)
    start, end = min(e.start for e in events), max(e.end for e in events)
    return max(start - t, t - end, 0.0)


def _measures(seg: Segment) -> list[float]:
    from .timing_diagram import _measures as measures

    return measures(seg)


def _exchange_events(seg: Segment) -> list[Event]:
    found = [seg.break_event] if seg.break_event else []
    return found + seg.contention + seg.command + seg.reply + seg.later[:LATER_SHOWN]


class Positions:
    """Where each event lies in a transcript's ``events`` (a list the link may still be
    appending to): the first index of an event equal to it, as a dict from every event to
    its first index gave. A transcript in time order (every one a capture or a link makes)
    is searched by bisection over the events themselves by their start times (``ordered``),
    nothing held an event, where the dict took some 90 bytes (an hour's capture: 357,000
    events, 32 MB held by every report of a passive judgement) and an array of the start
    times 8, with two lists of every start made to fill it (issue 22: ~9 MB at the first
    report of an hour's capture); one out of order, or with a start that is not a finite
    number, is indexed by the dict as before. ``tests/reports/test_evidence_positions.py``
    holds the two to the same answers."""

    def __init__(self, events: Sequence[Event]) -> None:
        self.events = events
        #: the events indexed so far are in start order, every start a finite number
        self.ordered = True
        self.first: dict[Event, int] = {}
        self._indexed = 0

    def index(self) -> None:
        """Take in the events appended since the last call."""
        events, at = self.events, self._indexed
        if self.ordered:
            last = events[at - 1].start if at else -math.inf
            isfinite = math.isfinite
            for e in islice(events, at, None):
                start = e.start
                if not (isfinite(start) and last <= start):
                    break
                last = start
            else:
                self._indexed = len(events)
                return
            self.ordered, at = False, 0  # out of order: the dict, from the first event
        for i in range(at, len(events)):
            self.first.setdefault(events[i], i)
        self._indexed = len(events)

    def of(self, events: Iterable[Event]) -> Iterator[int]:
        """The position of each of ``events`` found among those indexed (the rest left out)."""
        if not self.ordered:
            first = self.first
            return (first[e] for e in events if e in first)
        indexed, count = self.events, self._indexed
        found = (_first_at(indexed, count, e) for e in events)
        return (i for i in found if i is not None)


def _first_at(events: Sequence[Event], count: int, e: Event) -> int | None:
    """The first index among the first ``count`` of ``events`` (in start order) of an event
    equal to ``e``: equal events start at the same time."""
    start = e.start
    i = bisect_left(events, start, 0, count, key=_start_of)
    while i < count and events[i].start == start:
        if events[i] is e or events[i] == e:
            return i
        i += 1
    return None


_start_of = attrgetter("start")


#: The most events a recording's locator cuts into segments for one search: a finding whose
#: case attached evidence spread wider is searched for in the whole recording's cut, which
#: is read window by window (:class:`~..view.runs.LazyCut`), not made whole: a cut held ~1.5
#: KB an event, and a case's evidence of every measurement spread over the whole recording
#: (issue 22: 48 MB kept at 30 minutes of a measuring bus).
WIDE_POOL = 20_000
#: How many of its cuts a recording's locator keeps (a live run's: 64), each up to
#: :data:`WIDE_POOL` events: they are kept for the reports of every run of the judgement.
STREAMED_CUTS = 4


class StreamedPositions:
    """:class:`Positions` of a recording read again as its events come (``again()``: every
    event from the first, in recorded order), for exactly the events asked about: one read
    for those not placed before, stopped once each is found, nothing held of the rest
    (issue 22: a passive run's reports need no list of the recording's events). Each is
    placed at the first index of an event equal to it, as the dict from every event to its
    first index placed it (an equal event has an equal start, so only the events whose
    start is one asked about are compared); a recording does not grow, so what a read found
    or did not find stands. ``tests/reports/test_evidence_streamed.py`` holds it to
    :class:`Positions`."""

    def __init__(self, again: Callable[[], Iterable[Event]]) -> None:
        self.again = again
        self.first: dict[Event, int] = {}  # the events placed so far
        self.at: dict[int, Event] = {}  # and which is at each of their positions
        self.absent: set[Event] = set()  # asked about, and in no position
        self.reads = 0

    def index(self) -> None:
        """Nothing to take in: a recording does not grow."""

    def of(self, events: Iterable[Event]) -> Iterator[int]:
        """The position of each of ``events`` (those in none left out)."""
        events = list(events)
        first, absent = self.first, self.absent
        new = dict.fromkeys(e for e in events if e not in first and e not in absent)
        if new:
            self._place(new)
        return (first[e] for e in events if e in first)

    def _place(self, wanted: dict[Event, None]) -> None:
        """One read, up to the last of ``wanted`` found: each one's first position."""
        self.reads += 1
        starts = {e.start for e in wanted}
        left = len(wanted)
        first, at = self.first, self.at
        for i, e in enumerate(self.again()):
            if e.start in starts and e in wanted and e not in first:
                first[e], at[i] = i, e
                left -= 1
                if not left:
                    break
        self.absent.update(e for e in wanted if e not in first)


class Locator:
    """Finds the exchange behind each finding in one run's transcript ``events`` (a list the
    link may still be appending to: positions are indexed as it grows), or in a recording
    read again as its events come (:meth:`streamed`)."""

    def __init__(self, events: Sequence[Event], transcript: Transcript | None = None) -> None:
        """``transcript``: the one ``events`` belongs to, whose whole cut
        (:func:`~..view.runs.transcript_segments`) stands for a search of all its events."""
        self.events = events
        self.transcript = transcript
        self.position: Positions | StreamedPositions = Positions(events)
        self.again: Callable[[], Iterable[Event]] | None = None
        self._cuts: dict[tuple[int, int], Sequence[Segment]] = {}

    @classmethod
    def streamed(cls, again: Callable[[], Iterable[Event]], transcript: Transcript) -> Locator:
        """The locator of a recording (``transcript``, which does not grow) that reads its
        events only through ``again()`` (every event from the first, in order): the
        positions of the events it places and the stretches it cuts, each read as the
        events come, no list of them all (issue 22); the same answers as a locator over
        the list (``tests/reports/test_evidence_streamed.py``)."""
        locator = cls([], transcript)
        locator.again, locator.position = again, StreamedPositions(again)
        return locator

    def count(self) -> int:
        """How many events the run's transcript holds."""
        if self.again is not None and self.transcript is not None:
            return len(self.transcript)
        return len(self.events)

    def slice(self, lo: int, hi: int) -> list[Event]:
        """Events ``lo..hi-1`` (read as they come, for a streamed locator)."""
        if self.again is None:
            return list(self.events[lo:hi])
        return list(islice(self.again(), lo, hi)) if lo < hi else []

    def _at(self, placed: list[int]) -> list[Event]:
        """The events at positions ``placed`` (each one this locator placed)."""
        if isinstance(self.position, StreamedPositions):
            return [self.position.at[i] for i in placed]
        return [self.events[i] for i in placed]

    def _index(self) -> None:
        self.position.index()

    def _segments(self, lo: int, hi: int) -> Sequence[Segment]:
        """The exchanges among events ``lo..hi-1`` (cut once per range: a whole run's cut
        takes a fifth of a second)."""
        key = (lo, hi)
        if key not in self._cuts:
            if len(self._cuts) > (STREAMED_CUTS if self.again is not None else 64):
                self._cuts.clear()
            whole = self.transcript is not None and lo == 0 and hi == self.count()
            cut = whole_cut(self.transcript) if whole else segments(self.slice(lo, hi))
            if isinstance(cut, LazyCut):  # a command's segment: a transmission with characters
                self._cuts[key] = LazyCut(_with_chars(cut.transmissions))
            else:
                self._cuts[key] = [s for s in cut if s.command]
        return self._cuts[key]

    def _ref(self, events: Sequence[Event], exchange: str | None, how: str) -> WireRef | None:
        placed = sorted(self.position.of(events))
        wire = [e for e in self._at(placed) if e.kind is not EventKind.NOTE]
        if not wire:
            return None
        return WireRef(
            placed[0], placed[-1], min(e.start for e in wire), max(e.end for e in wire),
            exchange, how,
        )  # fmt: skip

    def _pick(self, finding: Finding, segs: Sequence[Segment]) -> tuple[list[Segment], str] | None:
        lines = [*finding.evidence, finding.detail]
        if finding.measured_ms is None:
            for line in lines:
                chained = _chain(line, segs)
                if chained:
                    return chained, "command"
        named = _named_in(segs, lines)  # the evidence lines' commands first, in their order
        stamps = [float(t) for line in lines for t in STAMP.findall(line)]
        if stamps and named:  # "reply to ?! at t=0.0387 s": the one nearest that time first
            named.sort(key=lambda s: min(_distance(s, t) for t in stamps))
        if finding.measured_ms is not None:
            nearest = _nearest_measured(named or segs, finding.measured_ms)
            if nearest is not None:
                distance, best = nearest
                if distance <= MEASURE_MATCH_MS:
                    return [best], "command and measured" if named else "measured"
        return ([named[0]], "command") if named else None

    def locate(self, finding: Finding, record: CaseRecord) -> WireRef | None:
        """The exchange ``finding`` (of ``record``'s case) rests on, or None (no wire)."""
        self._index()
        lo, hi = record.window if record.window else (0, self.count())
        held = [e for _, evs in record.evidence for e in evs] + record.evidence_beyond
        attached = sorted(set(self.position.of(held)))
        pools = []
        if attached:
            first, last = attached[0], attached[-1] + 1
            wide = self.again is not None and last - first > WIDE_POOL
            if wide or not record.evidence_whole:
                # a recording's whole cut (read as it comes), not a wide stretch cut whole
                # nor the first exchanges of the evidence alone (the rest not attached)
                first, last = 0, self.count()
            pools.append((first, last))
        pools.append((lo, hi))
        if lo > 0 and COMMAND.search(" ".join([*finding.evidence, finding.detail])):
            pools.append((0, hi))  # a reply the session cached from an earlier case
        for a, b in pools:
            found = self._pick(finding, self._segments(a, b))
            if found:
                chain, how = found
                events = [e for seg in chain for e in _exchange_events(seg)]
                return self._ref(events, " ".join(seg.text or "" for seg in chain), how)
        # no exchange named or measured: the case's own traffic (none known: no reference)
        own = self.slice(lo, hi) if record.window else []
        return self._ref(own or self._at(attached), None, "case")


def locator_of(link: BusEnd) -> Locator:
    """The one locator of a bus end's transcript, shared by every report that places
    findings on it (verdicts.json and report.html, and each run of a passive judgement,
    which all read the one loaded recording): a cut of an hour's capture takes seconds, and
    each report made its own, 2 per run and 11 runs for a bus of ten sensors. Its cuts stay
    true as the transcript grows, since a transcript is append-only. A recording's
    (``link.reads_again``) reads its events again as they come (:meth:`Locator.streamed`)."""
    transcript = link.transcript
    if link.reads_again:
        make = lambda: Locator.streamed(link.events_again, transcript)  # noqa: E731
    else:
        make = lambda: Locator(transcript.events, transcript)  # noqa: E731
    return memo(transcript, "_locator", None, make)


def wire_refs(cases: Sequence[CaseRecord], link: BusEnd) -> dict[int, WireRef]:
    """``id(finding)`` -> its reference, for every finding that needs evidence."""
    locator = locator_of(link)
    found: dict[int, WireRef] = {}
    for record in cases:
        for f in record.findings:
            if f.verdict in NEEDS_EVIDENCE:
                ref = locator.locate(f, record)
                if ref is not None:
                    found[id(f)] = ref
    return found
