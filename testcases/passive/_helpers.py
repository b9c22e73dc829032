"""What the passive cases share: every judge finding goes through the ``heard``
precondition, so a rule whose stimulus the recording does not hold is said the passive way."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from conformance import preconditions as precondition
from conformance.case import Case
from conformance.offline.heard import NOT_SEEN
from conformance.verdicts import Finding, Verdict


def judged(case: Case, findings: Iterable[Finding]) -> None:
    """Add the judges' findings, each through the ``heard`` precondition of its rule: one
    that observed nothing is "precondition not met: heard: not seen in the recording: ..."
    (never a PASS, never a FAIL); a finding that observed something holds it. A FAIL seen
    elsewhere in the recording stands beside an unheard part (the precondition is partial)."""
    for f in findings:
        if f.verdict is Verdict.INCONCLUSIVE and f.observed == 0:
            detail = f.detail if NOT_SEEN in f.detail else f"{NOT_SEEN}: {f.detail}"
            unmet = precondition.Unmet("heard", detail, tuple(f.evidence), partial=True)
            case.requires("heard", unmet, only=[f.requirement])
        else:
            case.requires("heard", None, only=[f.requirement])
            case.add(f)


def judged_only(case: Case, findings: Iterable[Finding], *ids: str) -> None:
    """:func:`judged` for the findings about ``ids`` alone."""
    judged(case, (f for f in findings if f.requirement in ids))


def heard(case: Case, items: Sequence[Any], what: str) -> bool:
    """True when the recording holds ``items`` (the traffic every rule of the case is
    about); otherwise each rule is INCONCLUSIVE, not seen in the recording: ``what``."""
    return case.requires("heard", precondition.overheard(items, what))


def unseen_rule(case: Case, rid: str, what: str) -> None:
    """One rule whose stimulus the recording does not hold, whatever its judge found."""
    case.requires("heard", precondition.Unmet("heard", f"{NOT_SEEN}: {what}"), only=[rid])
