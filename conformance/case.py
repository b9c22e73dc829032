"""The ``case`` fixture object: how a conformance case records findings and evidence.

A case names its requirement IDs with ``@pytest.mark.requirements(...)``, runs or reuses a
stimulus, hands the records to judges and adds their findings here. This object enforces the
contract: a finding must be about one of the case's requirements, a rule that the DUT's
claimed version does not bind becomes N/A instead of a verdict, and a requirement whose
declared precondition the wire did not show (:meth:`Case.requires`) is INCONCLUSIVE whatever
the case goes on to find about it.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable
from itertools import repeat
from math import isfinite
from operator import attrgetter
from typing import TYPE_CHECKING, Any

from .catalog import requirement
from .protocol.version import format_version
from .results import CaseRecord
from .tool_recorder.records import Exchange, Measurement
from .transcript import Event, EventKind
from .verdicts import Finding, Verdict, not_applicable

if TYPE_CHECKING:
    from .preconditions import Declaration, Unmet


#: Verdicts about the device, which a precondition the wire did not show voids.
JUDGED = (Verdict.PASS, Verdict.WARN, Verdict.FAIL)
#: What a precondition met only in part voids (:attr:`Unmet.partial`): a FAIL on what did
#: happen stands.
WHOLE = (Verdict.PASS, Verdict.WARN)


class Case:
    def __init__(
        self,
        record: CaseRecord,
        version: Any = None,
        preconditions: Declaration | None = None,
        *,
        evidence_events: bool = True,
        evidence_limit: int | None = None,
    ) -> None:
        self.record = record
        #: whether :meth:`evidence` keeps the events behind a record (False: its label
        #: alone, for a run that writes no report file, the only reader of the events)
        self.evidence_events = evidence_events
        #: how many events :meth:`evidence` keeps of one record at most (None: all), for a
        #: judged recording, whose evidence of "every measurement" grows with its length
        self.evidence_limit = evidence_limit
        self._version = version  # callable returning "13"/"14"/None, resolved lazily
        self.preconditions = preconditions  # None: the case declared nothing
        self._blocked: dict[str, Unmet] = {}  # requirement -> the precondition that failed

    @property
    def requirements(self) -> tuple[str, ...]:
        return self.record.requirements

    def expect(self, text: str) -> None:
        """What a conforming device does here, in one sentence, for the report."""
        self.record.expectation = text

    def add(self, *findings: Finding) -> None:
        self.extend(findings)

    def requires(self, code: str, unmet: Unmet | None, only: Iterable[str] | None = None) -> bool:
        """Apply the outcome of a declared precondition's check
        (:mod:`conformance.preconditions`): True when it held. When it did not, every
        requirement it guards is INCONCLUSIVE "precondition not met: <code>: ..." with the
        evidence, and a PASS, WARN or FAIL for it, found before or after, is dropped. A code
        the case did not declare is a case bug (ERROR), so a declaration cannot lag its code.
        ``only`` narrows the requirements voided to those of them (a rule whose FAIL is the
        very absence the precondition notes keeps that FAIL)."""
        guarded = self.preconditions.guarded(code) if self.preconditions else ()
        if only is not None and guarded:
            guarded = tuple(r for r in guarded if r in set(only)) or ()
            if not guarded:
                self._note(code, unmet)
                return unmet is None
        if not guarded:
            for rid in self.record.requirements:
                self.record.findings.append(
                    Finding(
                        rid,
                        Verdict.ERROR,
                        f"case bug: precondition {code!r} checked but not declared",
                        test=self.record.nodeid,
                    )
                )
            return unmet is None
        if unmet is not None and unmet.code != code:
            raise ValueError(f"precondition {code!r} checked with a {unmet.code!r} outcome")
        self._note(code, unmet)
        if unmet is None:
            return True
        for rid in guarded:
            if rid in self._blocked:
                continue
            self._blocked[rid] = unmet
            voided = _voided(unmet)
            self.record.findings = [
                f
                for f in self.record.findings
                if not (f.requirement == rid and f.verdict in voided)
            ]
            self._append(self._versioned(unmet.finding(rid)))
        return False

    def _note(self, code: str, unmet: Unmet | None) -> None:
        """Record the check for the report: the first reason it failed stands over a later
        "met" (a code checked per requirement may hold for one and not another)."""
        if unmet is not None:
            self.record.preconditions.setdefault(code, unmet.text)
            if self.record.preconditions[code] == "met":
                self.record.preconditions[code] = unmet.text
        else:
            self.record.preconditions.setdefault(code, "met")

    def _versioned(self, f: Finding) -> Finding:
        """N/A for a rule the DUT's claimed version does not bind, whatever was found."""
        version = self._version() if callable(self._version) else self._version
        if version and not requirement(f.requirement).applies_to_version(version):
            return not_applicable(
                f.requirement,
                f"rule binds SDI-12 v1.4 only; the DUT claims v{format_version(version)}",
                test=self.record.nodeid,
            )
        return f

    def extend(self, findings: Iterable[Finding]) -> None:
        version = self._version() if callable(self._version) else self._version
        for f in findings:
            f.test = f.test or self.record.nodeid
            if f.requirement not in self.record.requirements:
                f = Finding(
                    f.requirement,
                    Verdict.ERROR,
                    f"case bug: finding for {f.requirement}, which the case does not declare "
                    f"({f.detail})",
                    test=self.record.nodeid,
                )
            elif version and not requirement(f.requirement).applies_to_version(version):
                f = not_applicable(
                    f.requirement,
                    f"rule binds SDI-12 v1.4 only; the DUT claims v{format_version(version)}",
                    test=self.record.nodeid,
                )
            elif f.requirement in self._blocked and f.verdict in _voided(
                self._blocked[f.requirement]
            ):
                continue  # its precondition failed: the INCONCLUSIVE saying so stands
            self._append(f)

    def _append(self, f: Finding) -> None:
        f.test = f.test or self.record.nodeid
        self.record.findings.append(f)

    def not_applicable(self, reason: str, requirements: Iterable[str] | None = None) -> None:
        for rid in requirements or self.record.requirements:
            self.add(not_applicable(rid, reason))

    def evidence(self, label: str, record: Any) -> None:
        """Attach the wire events behind a record (Exchange, Measurement or events). Where
        the run writes no report file (a matrix row's runs: only the report files read the
        events) the label is attached with no events, the record's kind checked as
        :func:`events_of` checks it (a case handing something else is the same ERROR):
        joining and sorting ~10^5 events a row was ~1% of its CPU (issue 22). Past
        :attr:`evidence_limit` events, only the first exchanges up to it are kept and the
        label says how many of how many (:func:`head_of`)."""
        limit = self.evidence_limit
        if self.evidence_events and limit is not None:
            events, count, last = events_head(record, limit + 1)
            if count > limit:
                kept = head_of(events, limit)
                label = (
                    f"{label} (the first {len(kept)} of {count} events, up to "
                    f"t={kept[-1].end:.4f} s; the recording holds the rest)"
                )
                assert last is not None
                self.record.evidence_beyond.append(last)
                events = kept
            self.record.evidence.append((label, events))
        elif self.evidence_events:
            self.record.evidence.append((label, events_of(record)))
        else:
            _check_kinds(record)
            self.record.evidence.append((label, []))


def events_head(record: Any, n: int) -> tuple[list[Event], int, Event | None]:
    """The first ``n`` of :func:`events_of` ``(record)``, how many it holds and its last,
    without the list of them all: a judged recording's evidence of every measurement is
    ~10^5 events at 30 minutes, each made from the store as it is read (issue 22: 11 MB
    made at once to keep 1000). A list's records are joined one at a time and the first
    ``n`` kept as they come (by start, then join order: what the stable sort gives). Where a
    start is NaN, :func:`events_of` itself (its order is the parts')."""
    alone = record is None or (
        isinstance(record, (list, tuple)) and all(map(isinstance, record, repeat(Event)))
    )  # events alone: as they are (they are held already)
    if not alone:
        seen, total = 0, 0.0
        heads: list[tuple[float, int, Event]] = []  # (-start, -seen): the latest on top
        last: Event | None = None
        for part in record if isinstance(record, (list, tuple)) else [record]:
            found: list[Event] = []
            _join(part, found)
            for e in found:
                total += e.start
                if last is None or e.start >= last.start:
                    last = e  # the sort's last: the greatest start, the last joined of it
                if len(heads) < n:
                    heapq.heappush(heads, (-e.start, -seen, e))
                elif e.start < -heads[0][0]:  # (an equal start joined later is not before)
                    heapq.heapreplace(heads, (-e.start, -seen, e))
                seen += 1
        if isfinite(total):
            return [e for _, _, e in sorted(heads, reverse=True)], seen, last
    events = events_of(record)
    return events[:n], len(events), events[-1] if events else None


def head_of(events: list[Event], limit: int) -> list[Event]:
    """The first of ``events`` (in time order) up to ``limit`` of them, cut before the last
    break among them so no exchange is shown in part, where that keeps half of them or more
    (else all ``limit``: one exchange, a long binary packet, would leave a handful). Why: a
    judged recording's evidence of every measurement of an hour held ~10^5 events per case
    until the report was written, and the report listed them all (issue 22); the first
    exchanges show what the case saw, the recording holds the rest."""
    if len(events) <= limit:
        return events
    head = events[:limit]
    if events[limit].kind is EventKind.BREAK:
        return head  # the next exchange starts just past the limit
    for i in range(len(head) - 1, limit // 2 - 1, -1):
        if head[i].kind is EventKind.BREAK:
            return head[:i]
    return head  # an exchange longer than half the limit (a binary packet): shown in part


def _voided(unmet: Unmet) -> tuple[Verdict, ...]:
    return WHOLE if unmet.partial else JUDGED


_START = attrgetter("start")  # an event's start (a C getter: events are sorted by it often)


def events_of(record: Any) -> list[Event]:
    """Every bus event behind an Exchange, a Measurement, or a list of them, in time order
    (a list of events alone: copied as it is).

    The events of every record inside are joined unsorted and sorted once, stably, by
    start: what sorting each record's events, then the joined lists again (:func:`_nested`,
    this function until matrix21) gives, since a stable sort orders equal starts by their
    place and a sorted part keeps its equal starts in their order; a run's evidence lists
    (~100,000 events a fault-matrix row, a measurement's three times over) took ~27 ms.
    Except where a start is NaN, which orders nothing: then sorted as before, part by
    part."""
    if record is None:
        return []
    if isinstance(record, (list, tuple)) and all(map(isinstance, record, repeat(Event))):
        # (asked of a whole run's events, too: in C, not a generator step per event)
        return list(record)
    found: list[Event] = []
    _join(record, found)
    if not isfinite(sum(map(_START, found))):  # a NaN (or an infinity, or an overflow)
        return _nested(record)
    found.sort(key=_START)
    return found


def _check_kinds(record: Any) -> None:
    """The ``TypeError`` :func:`_join` raises for ``record`` where it raises one, without
    joining any events."""
    if record is None or isinstance(record, (Event, Exchange)):
        return
    if isinstance(record, (list, tuple)) and all(map(isinstance, record, repeat(Event))):
        return  # a run's events: in C (as events_of)
    if isinstance(record, Measurement):
        _check_kinds(record.start)
        for ex in record.data:
            _check_kinds(ex)
    elif isinstance(record, (list, tuple)):
        for r in record:
            _check_kinds(r)
    else:
        raise TypeError(f"no events in {type(record).__name__}")


def _join(record: Any, found: list[Event]) -> None:
    """The events behind ``record`` added to ``found`` in :func:`_nested`'s order, unsorted."""
    if record is None:
        return
    if isinstance(record, Event):
        found.append(record)
    elif isinstance(record, Exchange):
        for a in record.attempts:
            found += a.stray_events
            if a.break_event is not None:
                found.append(a.break_event)
            found += a.command_events + a.reply_events
    elif isinstance(record, Measurement):
        _join(record.start, found)
        found += record.waited_events
        for ex in record.data:
            _join(ex, found)
    elif isinstance(record, (list, tuple)):
        for r in record:
            _join(r, found)
    else:
        raise TypeError(f"no events in {type(record).__name__}")


def _nested(record: Any) -> list[Event]:
    """:func:`events_of` sorting each record's events, then the joined lists again: where a
    start is NaN the order a sort gives depends on the order it is given, so it is given
    the parts as ever."""
    if record is None:
        return []
    if isinstance(record, Event):
        return [record]
    if isinstance(record, Exchange):  # its attempts' events joined as events_of joins them
        found: list[Event] = []
        _join(record, found)
        return sorted(found, key=_START)
    if isinstance(record, Measurement):
        found = _nested(record.start) + list(record.waited_events)
        for ex in record.data:
            found += _nested(ex)
        return sorted(found, key=_START)
    if isinstance(record, (list, tuple)):
        if all(map(isinstance, record, repeat(Event))):
            return list(record)
        found = []
        for r in record:
            found += _nested(r)
        found.sort(key=_START)
        return found
    raise TypeError(f"no events in {type(record).__name__}")
