"""The verdict model (design.md section 3, a contract): findings, their ordering, aggregation.

A finding is one judged fact about one requirement, with evidence. A requirement's verdict is
the worst of its findings in the order N/A < PASS < WARN < INCONCLUSIVE < FAIL; ERROR (the tool
failed) is reported apart and never hidden behind another verdict.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from enum import StrEnum
from typing import Any


class Verdict(StrEnum):
    NA = "N/A"
    PASS = "PASS"
    WARN = "WARN"
    INCONCLUSIVE = "INCONCLUSIVE"
    FAIL = "FAIL"
    ERROR = "ERROR"

    @property
    def rank(self) -> int:
        return _RANK[self]


_RANK = {
    Verdict.NA: 0,
    Verdict.PASS: 1,
    Verdict.WARN: 2,
    Verdict.INCONCLUSIVE: 3,
    Verdict.FAIL: 4,
    Verdict.ERROR: 5,
}

ORDER: tuple[Verdict, ...] = tuple(sorted(Verdict, key=lambda v: v.rank))


def worst(verdicts: Iterable[Verdict], default: Verdict = Verdict.NA) -> Verdict:
    result = None
    for v in verdicts:
        if result is None or v.rank > result.rank:
            result = v
    return default if result is None else result


@dataclass
class Finding:
    """One judged fact: a verdict on one requirement, with the evidence a reader needs.

    ``measured_ms``/``limit_ms``/``uncertainty_ms`` are filled by timing judges; ``evidence``
    holds escaped wire text or other short observations; ``decision`` cites a
    requirements.md section 5 decision (``"A13"``) that shaped the verdict.
    """

    requirement: str
    verdict: Verdict
    detail: str
    test: str = ""
    measured_ms: float | None = None
    limit_ms: float | None = None
    uncertainty_ms: float | None = None
    evidence: list[str] = field(default_factory=list)
    decision: str | None = None
    # timing findings: how far (ms) the measurement sits from the edge that decided it, so
    # a verdict can be checked again against a larger uncertainty measured later in the run
    margin_ms: float | None = None

    def to_json(self) -> dict[str, Any]:
        d = asdict(self)
        d["verdict"] = str(self.verdict)
        return d


def passed(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.PASS, detail, **kw)


def failed(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.FAIL, detail, **kw)


def warned(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.WARN, detail, **kw)


def inconclusive(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.INCONCLUSIVE, detail, **kw)


def not_applicable(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.NA, detail, **kw)
