"""From per-case findings to per-requirement verdicts and the overall verdict (design.md 3).

Pure functions over records; the plugin feeds them and the reports read them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .catalog import Requirement, for_role
from .selection import NOT_SELECTED
from .transcript import Event
from .verdicts import Finding, Verdict, inconclusive, worst

#: the verdicts each finding is asked about, as module constants: a member read off the enum goes
#: through its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_PASS, _INCONCLUSIVE = Verdict.PASS, Verdict.INCONCLUSIVE
_WARN_OR_FAIL = (Verdict.WARN, Verdict.FAIL)

COMPLIANT = "COMPLIANT"
NON_COMPLIANT = "NON-COMPLIANT"
INCOMPLETE = "INCOMPLETE"


@dataclass
class CaseRecord:
    """What one conformance case did: its findings and the wire evidence behind them."""

    nodeid: str
    name: str
    requirements: tuple[str, ...]
    description: str = ""
    expectation: str = ""
    findings: list[Finding] = field(default_factory=list)
    evidence: list[tuple[str, list[Event]]] = field(default_factory=list)
    duration: float = 0.0
    verdict: Verdict = Verdict.NA
    # the transcript events (positions lo..hi-1) the case's run added; a whole-run case's
    # starts at 0, since it judges all of them (reports.evidence looks exchanges up there)
    window: tuple[int, int] | None = None
    #: declared precondition code -> "met" or the "precondition not met: ..." text, for each
    #: one the case checked (conformance/preconditions.py)
    preconditions: dict[str, str] = field(default_factory=dict)
    #: the transcript events the case itself added (a whole-run case's too, unlike
    #: ``window``) and the time it took on the link's clock: what a plan compares with
    added: tuple[int, int] | None = None
    bus_s: float | None = None
    #: the last event of each piece of :attr:`evidence` kept only in part (a judged
    #: recording's first exchanges, :attr:`~.case.Case.evidence_limit`): with them the
    #: reports place the case on the whole stretch it judged, and look for its findings'
    #: exchanges in the whole recording (:meth:`~.reports.evidence.Locator.locate`)
    evidence_beyond: list[Event] = field(default_factory=list)

    @property
    def evidence_whole(self) -> bool:
        """Whether every piece of :attr:`evidence` holds all its events."""
        return not self.evidence_beyond

    def summarise(self) -> Verdict:
        self.verdict = worst((f.verdict for f in self.findings), default=Verdict.ERROR)
        return self.verdict


@dataclass
class RequirementResult:
    """One requirement's verdict for a run, with the findings and the cases behind it (what
    verdicts.json, the HTML table and the console summary show per requirement)."""

    requirement: Requirement
    verdict: Verdict
    findings: list[Finding]
    tests: list[str]
    judged: bool = True  # False: testable, but no case of this run looked at it
    selected: bool = True  # False: a partial run (-k, --req) left out every case judging it
    consequence_of: str | None = None  # a FAILed rule whose deviation probably caused this

    @property
    def one_line(self) -> str:
        """The evidence line a reader sees first: the finding that set the verdict."""
        for f in self.findings:
            if f.verdict is self.verdict:
                return f.detail
        return ""


def aggregate(
    role: str, cases: list[CaseRecord], not_selected: frozenset[str] = frozenset()
) -> list[RequirementResult]:
    """Every catalog requirement of ``role`` with the worst verdict of its findings.

    A testable requirement that no case judged is INCONCLUSIVE (a hole in the certificate,
    never a silent PASS); an untestable one is N/A with the reason it cannot be tested here.
    One in ``not_selected`` (a partial run left out its cases) is N/A, marked not selected,
    and counts neither for nor against the verdict.
    """
    by_id: dict[str, list[Finding]] = {}
    tests: dict[str, list[str]] = {}
    for case in cases:
        for f in case.findings:
            by_id.setdefault(f.requirement, []).append(f)
        for rid in case.requirements:
            tests.setdefault(rid, []).append(case.nodeid)
    results = []
    for req in for_role(role):
        findings = by_id.get(req.id, [])
        if not req.testable(role):
            reason = req.untestable_reason or "not testable by this tool"
            findings = [Finding(req.id, Verdict.NA, f"untestable here: {reason}")]
        elif not findings and req.id in not_selected:
            findings = [Finding(req.id, Verdict.NA, NOT_SELECTED)]
        elif not findings:
            findings = [Finding(req.id, Verdict.INCONCLUSIVE, "no case judged this requirement")]
        short = partial_only(req.id, counted(findings))
        if short is not None:
            findings = [short, *findings]
        verdict = worst(f.verdict for f in counted(findings))
        judged = not (req.testable(role) and req.id not in by_id)
        selected = judged or req.id not in not_selected
        tested = sorted(set(tests.get(req.id, [])))
        results.append(RequirementResult(req, verdict, findings, tested, judged, selected=selected))
    return results


def unreached(finding: Finding) -> bool:
    """An INCONCLUSIVE that rests on no observation: the case could not reach the rule (an
    exploration stopped early, a precondition failed). Unlike one over observations (an
    uncertainty straddling a limit), it says nothing against what another case judged."""
    return finding.verdict is _INCONCLUSIVE and finding.observed == 0


def decides(finding: Finding) -> bool:
    """A finding that judged its rule: a FAIL or WARN, or a PASS over the whole rule. A
    partial PASS (one clause checked) does not: a sensor that breaks another clause would
    not have shown it there (seed 4197: the exploration's one repeated D0 PASSed R-4.4.5-10
    while continuous-overwrites-data empties the buffer at aRn!, which the retention case,
    whose precondition no M-type measurement met, was built to send)."""
    if finding.verdict is _PASS:
        return not finding.partial
    return finding.verdict in _WARN_OR_FAIL


def counted(findings: list[Finding]) -> list[Finding]:
    """The findings that set a requirement's verdict: a case that could not reach the rule
    does not outvote one that judged it (:func:`decides`); beside a partial PASS only, it
    does, and the rule stays INCONCLUSIVE."""
    decided = any(decides(f) for f in findings)
    return [f for f in findings if not (decided and unreached(f))]


def partial_only(rid: str, findings: list[Finding]) -> Finding | None:
    """An INCONCLUSIVE for ``rid`` where what its counted ``findings`` PASS is partial PASSes
    only (one clause of the rule checked, no case judged the whole of it): a PASS there
    would report the rule held where only a clause was seen to (a ``-k`` run of the
    exploration alone PASSed R-4.4.5-10 on repeated D0 reads, retention across breaks,
    standby and commands never tried). None where another finding decides or is worse."""
    if worst((f.verdict for f in findings), default=Verdict.NA) is not Verdict.PASS:
        return None
    if any(decides(f) for f in findings):
        return None
    parts = [f for f in findings if f.partial]
    return inconclusive(
        rid,
        "only one clause of the rule was checked ("
        + "; ".join(f"{f.test or 'a case'}: {f.detail}" for f in parts)
        + "): no case judged the rest of it",
        observed=sum(f.observed for f in parts),
    )


def overall(results: list[RequirementResult], *, strict: bool, complete: bool) -> str:
    verdicts = {r.verdict for r in results}
    if Verdict.FAIL in verdicts or (strict and Verdict.WARN in verdicts):
        return NON_COMPLIANT
    left_unjudged = any(r.selected and not r.judged for r in results)
    if not complete or Verdict.ERROR in verdicts or left_unjudged:
        return INCOMPLETE  # interrupted, the tool failed, or a selected case judged nothing
    return COMPLIANT


def counts(results: list[RequirementResult]) -> dict[str, int]:
    tally = {
        str(v): 0
        for v in (
            Verdict.PASS,
            Verdict.FAIL,
            Verdict.WARN,
            Verdict.INCONCLUSIVE,
            Verdict.NA,
            Verdict.ERROR,
        )
    }
    for r in results:
        if r.selected:  # a partial run counts what it selected
            tally[str(r.verdict)] += 1
    return tally
