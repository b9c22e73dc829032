"""Judge of what the recorder logged against what the played sensors sent (issue 20).

The wire shows which values the recorder collected; only the recorder's own report (the
harness's ``log`` lines, the trigger's ``SDI12_LOG_FILE``, an in-process program's output)
shows what it wrote down. Per measurement the two must agree in count, order, sign, digits
and decimal point. Values are compared as numbers (the catalog's note on R-4.4-02): a logger
stores numbers, so ``+1.50`` logged as ``1.5`` is the same value, ``+1013.25`` logged as
``1013.2`` or ``-3.75`` as ``3.75`` is not. HB values compare at the precision of their type.

The rule this rests on is R-4.4-02 ("can log data from" every measurement family) and, for
aHA!/aHB!, R-5.4-01 ("including reading back their data"): the catalog's notes say why these
are the closest the standard has. No report at all is N/A, never a PASS.
"""

from __future__ import annotations

import math
import re
import struct
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from decimal import Decimal

from ...protocol.binary import DataType
from ...protocol.commands import CommandError, Kind, parse_command
from ...transcript import escape
from ...verdicts import Finding, Verdict, not_applicable
from ...view.segments import TranscriptView
from ..reply_validity import Reason
from ..tally import Tally
from .measurements import ObservedMeasurement, observed_measurements
from .replies import crc_context, data_values, reply_problem

LOGGED = "R-4.4-02"
HIGH_VOLUME = "R-5.4-01"
IDS = (LOGGED, HIGH_VOLUME)
NOTHING_REPORTED = "the recorder reported no logged values"
#: Values quoted in one finding line (the recorder's words are untrusted and unbounded).
SHOWN_VALUE = 24

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_FLOAT_WORDS = {"nan", "+nan", "-nan", "inf", "+inf", "-inf", "infinity", "+infinity", "-infinity"}
_HIGH_VOLUME_KINDS = (Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY)


@dataclass(frozen=True)
class LogReport:
    """What the recorder says it logged in one scenario.

    ``logged`` is None when it said nothing about it (a harness without ``log`` lines, a
    trigger that wrote no ``SDI12_LOG_FILE``): nothing to compare, never a PASS. ``problem``
    says why a report it did make could not be read (a malformed log file, naming the line).
    """

    scenario: str
    logged: dict[str, list[str]] | None
    problem: str | None = None
    #: the scenario did not run to its end (the driver failed): without a report it had no
    #: chance to make one, so its measurements are not held against it
    cut_short: bool = False


@dataclass(frozen=True)
class Sent:
    """One value as the sensor sent it: its text and, for an HB value, its data type."""

    text: str
    dtype: DataType | None = None

    def key(self, logged: str) -> object | None:
        """``logged`` read as this value's kind of number (None: it is not one)."""
        if self.dtype in (DataType.FLOAT32, DataType.FLOAT64):
            if not (_NUMBER.fullmatch(logged) or logged.lower() in _FLOAT_WORDS):
                return None
            value = float(logged)
            if self.dtype is DataType.FLOAT32 and math.isfinite(value):
                try:
                    value = struct.unpack("<f", struct.pack("<f", value))[0]
                except OverflowError:
                    return math.inf
            return "nan" if math.isnan(value) else value
        return Decimal(logged) if _NUMBER.fullmatch(logged) else None

    def matches(self, logged: str) -> bool:
        mine = self.key(self.text)
        return mine is not None and self.key(logged) == mine

    def why_not(self, logged: str) -> str:
        """Why ``logged`` is not this value, in words a logger's maker can act on."""
        if self.key(logged) is None:
            return "not a number"
        flipped = logged[1:] if logged[:1] in "+-" else logged
        if self.matches("-" + flipped) or self.matches(flipped):
            return "its sign lost" if self.text.startswith("-") else "a sign it did not have"
        if len(logged) < len(self.text) and self.text.lstrip("+").startswith(logged.lstrip("+")):
            return "digits cut off"
        return "other digits or decimal point"


def _value(text: str) -> str:
    shown = escape(text)
    return shown if len(shown) <= SHOWN_VALUE else shown[: SHOWN_VALUE - 3] + "..."


def compare(sent: Sequence[Sent], logged: Sequence[str]) -> str | None:
    """What is wrong with ``logged`` as the record of ``sent`` (None: nothing)."""
    good = [s.matches(v) for s, v in zip(sent, logged, strict=False)]
    if len(logged) != len(sent):
        n, m = len(logged), len(sent)
        said = f"logged {n} value(s), the sensor sent {m}"
        if all(good) and n < m:
            return said + f": the last {m - n} missing, from {_value(sent[n].text)} on"
        if all(good):
            return said + f": {n - m} extra, from {_value(logged[m])} on"
        i = good.index(False)
        return said + f"; value {i + 1} is {_value(logged[i])}, sent {_value(sent[i].text)}"
    wrong = [i for i, ok in enumerate(good) if not ok]
    if not wrong:
        return None
    if Counter(sent[i].key(sent[i].text) for i in wrong) == Counter(
        sent[i].key(logged[i]) for i in wrong
    ):
        i = wrong[0]
        return (
            f"values logged in another order: value {i + 1} is {_value(logged[i])}, "
            f"the sensor sent {_value(sent[i].text)} there"
        )
    i = wrong[0]
    more = f" ({len(wrong)} of {len(sent)} values wrong)" if len(wrong) > 1 else ""
    return (
        f"value {i + 1} logged as {_value(logged[i])}, the sensor sent {_value(sent[i].text)}: "
        f"{sent[i].why_not(logged[i])}{more}"
    )


def same_values(sent: Sequence[str], logged: Sequence[str]) -> bool:
    """Whether ``logged`` records the ASCII values ``sent``, compared as numbers."""
    return compare([Sent(v) for v in sent], logged) is None


def _rid(command: str) -> str:
    try:
        kind = parse_command(command).kind
    except CommandError:
        return LOGGED
    return HIGH_VOLUME if kind in _HIGH_VOLUME_KINDS else LOGGED


def _sent_per_command(
    line: TranscriptView, taken: Sequence[ObservedMeasurement], part: int, uncertainty: float
) -> dict[str, list[Sent] | None]:
    """Per command text of scenario ``part``: the values its last measurement (or aRn!/aRCn!
    reply) brought in valid replies, or None where some data never came validly (the retry
    rules judge that measurement, not what was logged from it)."""
    found: dict[str, list[Sent] | None] = {}
    for m in taken:
        if m.start.part != part:
            continue
        unread = m.unread_indices()
        found[m.start.stem] = None if unread else [Sent(t, d) for t, d in m.sent_values()]
    crc = crc_context(line)
    for i, s in enumerate(line.transmissions):
        cmd = s.command
        if s.part != part or cmd is None or cmd.kind is not Kind.CONTINUOUS:
            continue
        if reply_problem(s, crc[i], uncertainty) is None:
            found[s.stem] = [Sent(v) for v in data_values(s, cmd)]
        else:
            found.setdefault(s.stem, None)
    return found


def _invalid_only(taken: Sequence[ObservedMeasurement], part: int) -> dict[str, list[Sent]]:
    """Per command text of scenario ``part`` whose last measurement has data indices that
    never came in a valid reply (parity, framing, format, a pause...): the values its valid
    replies did bring. A logger may log only those; values beyond them can only come from an
    invalid reply. A CRC mismatch is left out: R-4.4.12-07 judges what is logged after one."""
    found: dict[str, list[Sent]] = {}
    for m in taken:
        if m.start.part != part:
            continue
        found.pop(m.start.stem, None)
        unread = set(m.unread_indices())
        problems = [
            p for s, p in m.data if p is not None and (d := s.data_index) and d[1] in unread
        ]
        if unread and not any(p.reason is Reason.CRC_WRONG for p in problems):
            found[m.start.stem] = [Sent(t, d) for t, d in m.sent_values()]
    return found


def _never_collected(taken: Sequence[ObservedMeasurement], part: int) -> set[str]:
    """Command texts of scenario ``part`` whose last measurement announced values and was
    followed by no data command: the recorder asked for none, so an empty log of it says
    nothing of how it logs (R-4.4.5-05 and R-4.4.8-05 judge the collection never made; the
    Zephyr master of the twenty-seventh round dropped every ``aMC!`` so, docs/kit.md)."""
    last = {m.start.stem: m for m in taken if m.start.part == part}
    return {stem for stem, m in last.items() if m.count and not m.data}


def judge_logged_values(
    line: TranscriptView,
    reports: Sequence[LogReport],
    uncertainty: float,
    *,
    high_volume: bool = True,
) -> list[Finding]:
    """R-4.4-02 / R-5.4-01: per measurement of each scenario (``reports[i]`` is the recorder's
    account of ``line``'s part ``i``), the values logged are the values the sensor sent.

    A measurement on the wire missing from a report is a FAIL once the recorder reported
    what it logged anywhere in the run; values logged for a command it never sent are a
    FAIL; a report that could not be read is INCONCLUSIVE for its scenario. ``high_volume``
    False (a v1.3 recorder): R-5.4-01 is N/A."""
    if not any(r.logged is not None or r.problem for r in reports):
        return [not_applicable(rid, NOTHING_REPORTED) for rid in IDS]
    tally = Tally(IDS)
    if not high_volume:
        tally.not_applicable(HIGH_VOLUME, "the recorder does not claim v1.4")
    tally.unobservable(HIGH_VOLUME, "no aHA!/aHB! measurement with its values on the wire")
    unreadable: list[Finding] = []
    taken = observed_measurements(line, uncertainty)
    sent_texts = {(s.part, s.stem) for s in line.transmissions}
    for part, report in enumerate(reports):
        sent = _sent_per_command(line, taken, part, uncertainty)
        if report.problem is not None:
            rids = sorted({_rid(c) for c in sent} or {LOGGED})
            unreadable += [_unreadable(rid, report) for rid in rids]
            continue
        if report.logged is None and report.cut_short:
            continue
        logged = report.logged or {}
        invalid = _invalid_only(taken, part)
        uncollected = _never_collected(taken, part)
        for command, values in sent.items():
            if values is None:
                kept = invalid.get(command)
                got = logged.get(command)
                if kept is not None and got and len(got) > len(kept):
                    tally.fail(
                        _rid(command),
                        f"{report.scenario}: {escape(command)}",
                        f"logged {len(got)} value(s), only {len(kept)} came in valid replies: "
                        f"from {_value(got[len(kept)])} on they are from a reply that was not "
                        "valid",
                    )
                continue
            where = f"{report.scenario}: {escape(command)}"
            if command in uncollected and not logged.get(command):
                continue  # no values asked for, none logged: nothing to compare
            if command not in logged:
                if values:
                    none = " (no log report in this scenario)" if report.logged is None else ""
                    tally.fail(
                        _rid(command),
                        where,
                        f"the sensor sent {len(values)} value(s), none logged{none}",
                    )
                continue
            tally.observe(where, ids=[_rid(command)])
            problem = compare(values, logged[command])
            if problem is not None:
                tally.fail(_rid(command), where, problem)
        for command, values in logged.items():
            if command not in sent and values and (part, command) not in sent_texts:
                where = f"{report.scenario}: {escape(command)}"
                tally.fail(
                    _rid(command), where, f"{len(values)} value(s) logged, the command never sent"
                )
    findings = tally.findings("logged as sent: count, order, sign, digits, decimal point")
    return findings + unreadable


def _unreadable(rid: str, report: LogReport) -> Finding:
    return Finding(
        rid,
        Verdict.INCONCLUSIVE,
        f"scenario {report.scenario}: the recorder's report of what it logged could not be "
        f"read: {report.problem}",
        evidence=[f"scenario {report.scenario}"],
        observed=1,
    )
