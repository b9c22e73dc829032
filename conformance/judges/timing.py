"""Timing as metrology (design.md section 4): a measured interval with its uncertainty
against a limit, giving PASS, FAIL or an honest INCONCLUSIVE.

PASS only when the whole interval ``measured +/- uncertainty`` lies inside the allowed window
(widened by the spec's tolerance), FAIL only when the whole interval lies outside it.
"""

from __future__ import annotations

from ..protocol.timing import TOLERANCE
from ..verdicts import Finding, Verdict

EPSILON = 1e-9  # s: a value exactly on a limit is inside it, whatever float rounding says


def judge_window(
    requirement: str,
    what: str,
    measured: float,
    uncertainty: float,
    *,
    low: float | None = None,
    high: float | None = None,
    tolerance: float = TOLERANCE,
    should: bool = False,
    evidence: list[str] | None = None,
    decision: str | None = None,
) -> Finding:
    """Judge ``measured`` (s) against ``[low - tol, high + tol]``.

    ``should`` turns a definite violation into WARN (a SHOULD rule or a lenient decision).
    """
    lo = None if low is None else low - tolerance - EPSILON
    hi = None if high is None else high + tolerance + EPSILON
    m_lo, m_hi = measured - uncertainty, measured + uncertainty
    inside = (lo is None or m_lo >= lo) and (hi is None or m_hi <= hi)
    outside = (lo is not None and m_hi < lo) or (hi is not None and m_lo > hi)
    if inside:
        verdict = Verdict.PASS
    elif outside:
        verdict = Verdict.WARN if should else Verdict.FAIL
    else:
        verdict = Verdict.INCONCLUSIVE
    limit = _describe_limit(lo, hi)
    detail = f"{what}: {measured * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} ms, allowed {limit}"
    if verdict is Verdict.INCONCLUSIVE:
        detail += " (the uncertainty straddles the limit)"
    limit_ms = (hi if hi is not None else lo) or 0.0
    return Finding(
        requirement,
        verdict,
        detail,
        measured_ms=round(measured * 1e3, 3),
        limit_ms=round(limit_ms * 1e3, 3),
        uncertainty_ms=round(uncertainty * 1e3, 3),
        evidence=list(evidence or []),
        decision=decision,
    )


def _describe_limit(lo: float | None, hi: float | None) -> str:
    if lo is not None and hi is not None:
        return f"{lo * 1e3:.2f}..{hi * 1e3:.2f} ms"
    if hi is not None:
        return f"≤ {hi * 1e3:.2f} ms"
    if lo is not None:
        return f"≥ {lo * 1e3:.2f} ms"
    return "any"


def plural(what: str) -> str:
    return what[:-1] + "ies" if what.endswith("y") and not what.endswith("ay") else what + "s"


def combine(
    rid: str, findings: list[Finding], what: str, *, smallest_is_worst: bool = False
) -> Finding:
    """One finding per requirement out of many observations: the worst verdict (and, among
    equals, the largest measurement, or the smallest for minimum limits such as a break's
    length), with the range of all of them, so a reader sees one line per rule."""
    if not findings:
        return Finding(rid, Verdict.INCONCLUSIVE, f"no {what} was observed")
    sign = -1 if smallest_is_worst else 1
    worst = max(findings, key=lambda f: (f.verdict.rank, sign * abs(f.measured_ms or 0)))
    values = [f.measured_ms for f in findings if f.measured_ms is not None]
    count = f"{len(findings)} {plural(what) if len(findings) != 1 else what}"
    span = f"{count}, {min(values):.2f}..{max(values):.2f} ms" if values else ""
    if worst.verdict is Verdict.PASS and ", allowed " in worst.detail:
        detail = f"{span}; all inside the limit ({worst.detail.split(', allowed ')[-1]})"
    elif worst.verdict is Verdict.PASS:
        detail = f"{count} observed; {span + '; ' if span else ''}{worst.detail}"
    else:
        parts = [worst.detail]
        if worst.evidence and worst.evidence[0] not in worst.detail:
            parts[0] += f" [{worst.evidence[0]}]"  # where, when the detail does not say it
        if span:
            parts.append(span)
        detail = "; ".join(parts)
    return Finding(
        rid,
        worst.verdict,
        detail,
        measured_ms=worst.measured_ms,
        limit_ms=worst.limit_ms,
        uncertainty_ms=worst.uncertainty_ms,
        evidence=worst.evidence,
    )
