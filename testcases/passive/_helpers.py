"""What the passive cases share: the wording of a rule the recording did not exercise."""

from __future__ import annotations

from collections.abc import Iterable, Iterator

from conformance.offline.heard import NOT_SEEN
from conformance.verdicts import Finding, Verdict, inconclusive


def unseen(findings: Iterable[Finding]) -> Iterator[Finding]:
    """The judges' findings, with "nothing observed" said the passive way: the rule's
    stimulus is not in the recording (never a PASS, never a FAIL)."""
    for f in findings:
        if f.verdict is Verdict.INCONCLUSIVE and f.observed == 0 and NOT_SEEN not in f.detail:
            f.detail = f"{NOT_SEEN}: {f.detail}"
        yield f


def only(findings: Iterable[Finding], *ids: str) -> Iterator[Finding]:
    return unseen(f for f in findings if f.requirement in ids)


def not_seen(rid: str, what: str) -> Finding:
    return inconclusive(rid, f"{NOT_SEEN}: {what}")
