"""Collect violations for a fixed set of requirements over many observations, then give one
finding per requirement.

Judges look at many replies (every D reply of every measurement, say). A reader wants one
line per requirement: how many observations, and the first few that broke the rule.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..protocol.values import Violation
from ..verdicts import Finding, Verdict
from .cite import listed

SHOWN = 3  # offending observations quoted per finding
CHECKED_SHOWN = 160  # characters of a PASS finding's list of what was checked


class Seen:
    """The observations of one rule as a finding reads them: how many, and the distinct
    labels in first-seen order only as far as a PASS detail quotes them (their list cut at
    :data:`CHECKED_SHOWN` characters). Not every label: a windowed judge (issue 22) keeps a
    tally over an hour's replies, one f-string each, and the finding needs their count."""

    __slots__ = ("count", "labels", "_width")

    def __init__(self) -> None:
        self.count = 0
        self.labels: dict[str, None] = {}
        self._width = -2  # len(", ".join(labels))

    def append(self, where: str) -> None:
        self.count += 1
        if self._width <= CHECKED_SHOWN and where not in self.labels:
            self.labels[where] = None
            self._width += len(where) + 2

    def __len__(self) -> int:
        return self.count

    def checked(self) -> str:
        """``", ".join`` of every distinct label, cut as a PASS detail cuts it."""
        checked = ", ".join(self.labels)
        return checked[:157] + "..." if len(checked) > CHECKED_SHOWN else checked


class Tally:
    """Observations and violations for ``ids``; anything else given to it is ignored.

    ``where`` labels say which exchange an observation came from (``0MC!``, ``0D1!``...).
    """

    def __init__(self, ids: Iterable[str]) -> None:
        self.ids = tuple(ids)
        self.observed: dict[str, Seen] = {rid: Seen() for rid in self.ids}
        self.violations: dict[str, list[tuple[str, Violation]]] = {rid: [] for rid in self.ids}
        self.na: dict[str, str] = {}
        self.why_not: dict[str, str] = {}  # why a rule may end up with nothing to judge
        self.undecided: dict[str, list[str]] = {rid: [] for rid in self.ids}
        self.decisions: dict[str, str] = {}

    def observe(
        self, where: str, violations: Iterable[Violation] = (), ids: Iterable[str] | None = None
    ) -> None:
        """One observation bearing on ``ids`` (default: all of this tally's IDs)."""
        for rid in self.ids if ids is None else ids:
            if rid in self.observed:
                self.observed[rid].append(where)
        for v in violations:
            if v.requirement in self.violations:
                self.violations[v.requirement].append((where, v))

    def fail(self, rid: str, where: str, message: str, *, warning: bool = False) -> None:
        self.observe(where, [Violation(rid, message, warning)], ids=[rid])

    def not_applicable(self, rid: str, reason: str) -> None:
        self.na.setdefault(rid, reason)

    def unobservable(self, rid: str, reason: str) -> None:
        """Say why ``rid`` could not be observed here (its INCONCLUSIVE reason if nothing is)."""
        self.why_not.setdefault(rid, reason)

    def undecide(self, rid: str, where: str, reason: str) -> None:
        """An observation at ``where`` that could not decide ``rid``: unless a violation FAILs
        or WARNs it, the rule is INCONCLUSIVE (counted, so another observation's PASS does
        not stand for this one)."""
        if rid in self.undecided:
            self.undecided[rid].append(f"{where}: {reason}")

    def decision(self, rid: str, label: str) -> None:
        self.decisions[rid] = label

    def findings(self, ok: dict[str, str] | str = "conforms") -> list[Finding]:
        result = []
        for rid in self.ids:
            seen = self.observed[rid]
            bad = self.violations[rid]
            decision = self.decisions.get(rid)
            if bad:
                hard = [b for b in bad if not b[1].warning]
                verdict = Verdict.FAIL if hard else Verdict.WARN
                lines = _counted(f"{w}: {v.message}" for w, v in (hard or bad))
                result.append(
                    Finding(
                        rid,
                        verdict,
                        listed(lines, SHOWN),
                        decision=decision,
                        # the detail quotes SHOWN; the rest is kept here, not dropped, so
                        # the JSON and the report carry every offending observation
                        evidence=[*dict.fromkeys(w for w, _ in (hard or bad))][:SHOWN]
                        + [f"also: {line}" for line in lines[SHOWN:]]
                        + [f"{len(seen)} observation(s)"],
                        observed=len(seen),
                    )
                )
            elif self.undecided[rid]:
                lines = _counted(self.undecided[rid])
                result.append(
                    Finding(
                        rid,
                        Verdict.INCONCLUSIVE,
                        listed(lines, SHOWN),
                        decision=decision,
                        observed=len(seen) + len(self.undecided[rid]),
                    )
                )
            elif rid in self.na and not seen:
                result.append(Finding(rid, Verdict.NA, self.na[rid], decision=decision))
            elif not seen:
                reason = self.why_not.get(
                    rid, "nothing was observed that this rule could be judged on"
                )
                result.append(Finding(rid, Verdict.INCONCLUSIVE, reason, decision=decision))
            else:
                text = ok if isinstance(ok, str) else ok.get(rid, "conforms")
                checked = seen.checked()
                result.append(
                    Finding(
                        rid,
                        Verdict.PASS,
                        f"{text} ({len(seen)} checked: {checked})",
                        decision=decision,
                        observed=len(seen),
                    )
                )
        return result


def _counted(lines: Iterable[str]) -> list[str]:
    """Each distinct line once, with how often it came ("0M!: no reply (×2)"): the same
    violation in two scenarios is one fact for the reader, not a repeated sentence."""
    seen: dict[str, int] = {}
    for line in lines:
        seen[line] = seen.get(line, 0) + 1
    return [line if n == 1 else f"{line} (×{n})" for line, n in seen.items()]
