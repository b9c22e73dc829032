"""The verdict model (design.md section 3, a contract): findings, their ordering, aggregation.

A finding is one judged fact about one requirement, with evidence. A requirement's verdict is
the worst of its findings in the order N/A < PASS < WARN < INCONCLUSIVE < FAIL; ERROR (the tool
failed) is reported apart and never hidden behind another verdict.

Two rules hold for every finding, whichever judge builds it, because they are enforced here,
where a finding comes into being (issue 10):

- a PASS rests on something observed: a finding says how many exchanges, events or
  measurements it judged (``observed``); a PASS over none is INCONCLUSIVE, "nothing to judge";
- so does a FAIL or a WARN (issue 18): it names at least one observation (``observed >= 1``)
  and carries at least one evidence line (the escaped wire text it rests on); one without
  either is INCONCLUSIVE, "nothing under it", saying which was missing;
- a rule's level caps its verdict: a SHOULD or MAY rule that is broken is a WARN, never a
  FAIL (the catalog's level decides, :func:`conformance.catalog.strongest_verdict`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from enum import StrEnum
from typing import Any

from .catalog import strongest_verdict

#: The reason a PASS without any observation behind it became INCONCLUSIVE.
NOTHING_TO_JUDGE = "nothing to judge"
#: The reason a FAIL or WARN without an observation or evidence line became INCONCLUSIVE.
NOTHING_UNDER_IT = "nothing under it"


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


#: the verdicts every finding's check reads, as module constants: a member read off the enum goes
#: through its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_PASS, _WARN, _FAIL, _INCONCLUSIVE = Verdict.PASS, Verdict.WARN, Verdict.FAIL, Verdict.INCONCLUSIVE
_FAIL_OR_WARN = (Verdict.FAIL, Verdict.WARN)


def worst(verdicts: Iterable[Verdict], default: Verdict = Verdict.NA) -> Verdict:
    result = None
    for v in verdicts:
        if result is None or v.rank > result.rank:
            result = v
    return default if result is None else result


@dataclass
class Distribution:
    """What a timed rule measured, all of it: a maker wants to know that the firmware passes
    by 0.3 ms, not only that it passes (issue 24). Figures in ms.

    ``low_ms``/``high_ms`` are the edges the verdict used (the standard's limit widened by its
    tolerance), None where the rule has no such edge; ``mixed_limits`` says the observations
    were judged against different edges (a wait that depends on each measurement's ttt), so
    only the slack is comparable. ``slack_ms`` is each observation's distance to its nearer
    edge, positive inside, sampled to at most :data:`MAX_TICKS` (min and max always kept);
    ``values_ms`` the matching measurements. ``uncertainty_ms`` is the observations' median
    uncertainty (on a real link a few stamps near a host stall are far wider than the rest).
    """

    count: int
    min_ms: float
    median_ms: float
    max_ms: float
    low_ms: float | None
    high_ms: float | None
    uncertainty_ms: float
    margin_ms: float  # the smallest slack: negative when an observation is outside
    mixed_limits: bool = False
    set_aside: int = 0  # observations a real-time link's irregular stamps left undecided
    values_ms: list[float] = field(default_factory=list)
    slack_ms: list[float] = field(default_factory=list)

    def margin_in_uncertainty(self, uncertainty_ms: float | None = None) -> float | None:
        """The margin counted in uncertainties (None on an exact clock: any margin is
        decided there)."""
        u = self.uncertainty_ms if uncertainty_ms is None else uncertainty_ms
        return None if u <= 0 else round(self.margin_ms / u, 2)


#: ticks a distribution keeps for the report's strip chart (a run judges ~16,000 gaps)
MAX_TICKS = 240


@dataclass
class Finding:
    """One judged fact: a verdict on one requirement, with the evidence a reader needs.

    ``measured_ms``/``limit_ms``/``uncertainty_ms`` are filled by timing judges; ``evidence``
    holds escaped wire text or other short observations; ``decision`` cites a
    requirements.md section 5 decision (``"A13"``) that shaped the verdict. ``observed`` is the
    number of exchanges, events or measurements the verdict rests on: a PASS needs at least one,
    and a FAIL or WARN needs at least one and an evidence line. ``partial`` marks a PASS that
    checked one clause of its rule only (the exploration's repeated D0 judges repeated reads,
    not retention across the breaks, standby and commands the rule names): it stands beside
    the case built for the whole rule, never for it (:func:`conformance.results.counted`).
    It is the judges' knowledge, not the report's: verdicts.json leaves it out.
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
    observed: int = 0
    consequence_of: str | None = None  # the root finding's requirement (root_causes.py)
    # timing findings: every measurement the verdict rests on (issue 24, margins)
    distribution: Distribution | None = None
    partial: bool = False

    def __post_init__(self) -> None:
        if self.verdict is _PASS and self.observed < 1:
            self.verdict = _INCONCLUSIVE
            self.detail = f"{NOTHING_TO_JUDGE}: {self.detail}"
        if self.verdict in _FAIL_OR_WARN:
            missing = [
                what
                for what, lacking in (
                    ("no observation counted", self.observed < 1),
                    ("no evidence line", not self.evidence),
                )
                if lacking
            ]
            if missing:
                self.detail = (
                    f"{NOTHING_UNDER_IT} ({' and '.join(missing)}): would be "
                    f"{self.verdict}: {self.detail}"
                )
                self.verdict = _INCONCLUSIVE
        if self.verdict is _FAIL and strongest_verdict(self.requirement) == "WARN":
            self.verdict = _WARN
            self.detail += " (a SHOULD/MAY rule: broken, it is a WARN, never a FAIL)"

    def to_json(self) -> dict[str, Any]:
        d = asdict(self)
        del d["partial"]  # how the run weighs it, not a field of the report (contract)
        d["verdict"] = str(self.verdict)
        return d


def passed(requirement: str, detail: str, *, observed: int, **kw: Any) -> Finding:
    """A PASS over ``observed`` exchanges/events/measurements (none: INCONCLUSIVE)."""
    return Finding(requirement, Verdict.PASS, detail, observed=observed, **kw)


def failed(requirement: str, detail: str, **kw: Any) -> Finding:
    """A FAIL: pass ``observed`` and ``evidence`` (without them it is INCONCLUSIVE)."""
    return Finding(requirement, Verdict.FAIL, detail, **kw)


def warned(requirement: str, detail: str, **kw: Any) -> Finding:
    """A WARN: pass ``observed`` and ``evidence`` (without them it is INCONCLUSIVE)."""
    return Finding(requirement, Verdict.WARN, detail, **kw)


def inconclusive(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.INCONCLUSIVE, detail, **kw)


def not_applicable(requirement: str, detail: str, **kw: Any) -> Finding:
    return Finding(requirement, Verdict.NA, detail, **kw)
