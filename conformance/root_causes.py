"""Root causes: when one deviation drags other findings after it, say so (issue 10).

A sensor slow to wake after a break misses the command that follows the break; a measurement
a break failed to abort sends its service request over later traffic; a recorder that retries
over a reply sees its own command come apart on the line. Each later FAIL is real on the
wire and stays a FAIL, but a reader should fix the first deviation first. So after
aggregation every FAIL or WARN of a rule that a FAILed rule is known to drag after it is
linked to that root ("probably a consequence of R-7.0-07 ..."), and the reports list roots
first. The table is the one place that knows which deviation drags which.
"""

from __future__ import annotations

from collections.abc import Iterable

from .results import RequirementResult
from .verdicts import Verdict

#: root rule -> rules whose violation commonly follows from it, with why (one line each).
DRAGS: dict[str, tuple[tuple[str, ...], str]] = {
    # sensor role
    "R-7.0-07": (
        ("R-7.0-05", "R-7.0-04", "R-4.4.5.1-03"),
        "a sensor slow to wake misses a command sent right after the break",
    ),
    # not R-7.0-09: a reply after a retry that is early only as the retry's reply, and late
    # as the try's before it, is judged neither way (judges.wire), so an R-7.0-09 FAIL beside
    # a late reply has a cause of its own (a sensor's break before its reply, say)
    "R-7.0-10": (
        ("R-4.2-03", "R-4.3-01", "R-4.4-01", "R-7.0-12"),
        "a late reply runs into the recorder's retry",
    ),
    "R-4.4.5.1-01": (
        ("R-4.0-01", "R-4.4.6-01", "R-4.4.5.1-02", "R-4.4.5.1-03"),
        "a measurement the break did not abort still sends its service request later",
    ),
    "R-7.0-15": (
        ("R-7.0-14", "R-7.0-03"),
        "a sensor that never sleeps answers whatever follows, a short pulse included",
    ),
    "R-4.4.7-02": (("R-4.4.7-08",), "an aC! answered 'a00000' starts no measurement"),
    # an unknown-command text (issue 18): text where an empty reply or silence is due
    "R-4.4.8.1-03": (
        (
            "R-4.4.5-01",
            "R-4.4.7-01",
            "R-4.4.11-01",
            "R-4.4.8.1-01",
            "R-4.4.8.1-02",
            "R-4.4.12-03",
            "R-4.4.12-05",
            "R-6.2-06",
        ),
        "a sensor that answers what it does not serve with text of its own (such as 'aUNKN')"
        " gives that text to every command it does not serve",
    ),
    # recorder role
    "R-7.2-06": (("R-7.0-13",), "a retry that talks over a reply comes apart on the line"),
    "R-7.0-02": (
        ("R-7.0-17", "R-7.1-01"),
        "spacing too short to be a break leaves the command after it without one",
    ),
    "R-7.1-01": (("R-7.0-17",), "a late aD0! without a break is also a command without one"),
    "R-4.4.5-06": (
        ("R-4.4.5-05", "R-4.4.5-07"),
        "a recorder that turns to another sensor misses the first one's service request",
    ),
}

BAD = (Verdict.FAIL, Verdict.WARN)


def link(results: Iterable[RequirementResult]) -> list[RequirementResult]:
    """Mark every FAIL/WARN that a FAILed root drags after it; return the roots with at
    least one consequence. Findings keep their verdicts; their detail names the root."""
    by_id = {r.requirement.id: r for r in results}
    roots = []
    for root_id, (dragged, why) in DRAGS.items():
        root = by_id.get(root_id)
        if root is None or root.verdict is not Verdict.FAIL:
            continue
        anchor = _anchor(root)
        linked = False
        for rid in dragged:
            result = by_id.get(rid)
            if result is None or result.verdict not in BAD or result.consequence_of:
                continue
            result.consequence_of = root_id
            for f in result.findings:
                if f.verdict in BAD:
                    f.consequence_of = root_id
                    f.detail += f" (probably a consequence of {root_id}{anchor}: {why})"
            linked = True
        linked = _link_preconditions(by_id.values(), root_id, anchor) or linked
        if linked:
            roots.append(root)
    for r in by_id.values():  # a precondition tied to a root that did not FAIL names none
        for f in r.findings:
            if f.verdict is Verdict.INCONCLUSIVE and f.consequence_of != r.consequence_of:
                f.consequence_of = None
    return roots


def _link_preconditions(results: Iterable[RequirementResult], root_id: str, anchor: str) -> bool:
    """An INCONCLUSIVE whose case named ``root_id`` as the reason its precondition failed
    (the sensor never shown in standby, say) is linked to that FAILed root too."""
    linked = False
    for result in results:
        if result.verdict is not Verdict.INCONCLUSIVE or result.consequence_of:
            continue
        tied = [f for f in result.findings if f.consequence_of == root_id]
        if tied:
            result.consequence_of = root_id
            for f in tied:
                f.detail += f" (probably a consequence of {root_id}{anchor})"
            linked = True
    return linked


def reading_order(results: Iterable[RequirementResult]) -> list[RequirementResult]:
    """Roots first, each followed by what it drags; then the rest in the order given."""
    results = list(results)
    ids = {r.requirement.id for r in results}
    roots = [r for r in results if any(c.consequence_of == r.requirement.id for c in results)]
    ordered: list[RequirementResult] = []
    for root in roots:
        ordered.append(root)
        ordered += [c for c in results if c.consequence_of == root.requirement.id]
    placed = {r.requirement.id for r in ordered}
    ordered += [r for r in results if r.requirement.id not in placed]
    assert {r.requirement.id for r in ordered} == ids
    return ordered


def _anchor(root: RequirementResult) -> str:
    """ " at t=1.234 s" from the root's FAIL finding when its evidence has a time."""
    for f in root.findings:
        if f.verdict is not Verdict.FAIL:
            continue
        for line in [f.detail, *f.evidence]:
            at = line.find("t=")
            if at >= 0:
                stamp = line[at:].split()[0].rstrip(",;)]")
                return f" at {stamp} s" if not stamp.endswith("s") else f" at {stamp}"
    return ""
