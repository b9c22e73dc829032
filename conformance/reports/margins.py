"""How close every timed rule came to its limit (issue 24): the rows of ``verdicts.json``'s
``margins`` and the strip chart of ``report.html``.

A verdict says a reply started in time; a firmware team wants to know by how much, and whether
a change ate into the margin. One strip per timed rule: every measurement a tick, the limit a
line, the band of the run's measured uncertainty around it shaded (inside that band the tool
could not tell and says INCONCLUSIVE). A rule whose observations were judged against different
limits (a wait that depends on each measurement's ttt) is drawn as its slack to the limit.

Drawn from the findings' :class:`~conformance.verdicts.Distribution`, the same figures the
judges decided on, so the chart cannot disagree with a verdict. Inline SVG, no script.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from html import escape
from typing import Any

from ..results import RequirementResult
from ..verdicts import Distribution, Finding

WIDTH = 700  # px: the whole strip fits an A4 page printed at 100 %
LABEL = 140  # px for the requirement on the left
FIGURES = 190  # px for the figures on the right
PLOT = WIDTH - LABEL - FIGURES
ROW = 44


def timed(results: list[RequirementResult]) -> list[tuple[RequirementResult, Finding, int]]:
    """Each timed rule with the finding of its smallest margin and its count of measurements."""
    rows = []
    for r in results:
        found = [f for f in r.findings if f.distribution is not None]
        if found:
            closest = min(found, key=lambda f: f.distribution.margin_ms)  # type: ignore[union-attr]
            rows.append((r, closest, sum(f.distribution.count for f in found)))  # type: ignore[union-attr]
    return rows


def distribution_json(f: Finding) -> dict[str, Any] | None:
    """A finding's distribution for ``verdicts.json``, with the uncertainty the verdict was
    finally judged with (a later, larger one re-judges it: :func:`~.timing.recheck`)."""
    d = f.distribution
    if d is None:
        return None
    shown = asdict(d)
    shown["uncertainty_ms"] = _uncertainty(f, d)
    shown["margin_uncertainties"] = d.margin_in_uncertainty(f.uncertainty_ms)
    return shown


def margins_json(results: list[RequirementResult]) -> list[dict[str, Any]]:
    """``verdicts.json``'s ``margins``: one row per timed rule."""
    rows = []
    for r, f, count in timed(results):
        d = distribution_json(f) or {}
        rows.append(
            {
                "requirement": r.requirement.id,
                "verdict": str(r.verdict),
                "test": f.test,
                "count": count,
                **{k: d[k] for k in ("min_ms", "median_ms", "max_ms", "low_ms", "high_ms")},
                "uncertainty_ms": d["uncertainty_ms"],
                "margin_ms": d["margin_ms"],
                "margin_uncertainties": d["margin_uncertainties"],
                "mixed_limits": d["mixed_limits"],
            }
        )
    return rows


def _uncertainty(f: Finding, d: Distribution) -> float:
    """The band drawn: the finding's own uncertainty (its worst observation's, or the larger
    one :func:`~conformance.judges.timing.recheck` re-judged it with), else the typical."""
    return f.uncertainty_ms if f.uncertainty_ms is not None else d.uncertainty_ms


def nice_ticks(lo: float, hi: float, most: int = 5) -> list[float]:
    """Round axis values between ``lo`` and ``hi`` (1, 2 or 5 times a power of ten apart)."""
    span = hi - lo
    if span <= 0:
        return [lo]
    raw = span / most
    power = 10 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1, 2, 5, 10) if m * power >= raw)
    first = math.ceil(lo / step) * step
    return [round(first + i * step, 9) for i in range(int((hi - first) / step + 1e-9) + 1)]


def _fmt(ms: float) -> str:
    return f"{ms:.2f}" if abs(ms) < 100 else f"{ms:.1f}"


_COLOUR = {"PASS": "#1b7a1b", "FAIL": "#b3261e", "WARN": "#a86400", "INCONCLUSIVE": "#6b4fa0"}


def _places(ticks: list[float]) -> int:
    """Decimals that tell the axis values apart (0 for 2000/2002/2004, 1 for 149.5/150.0)."""
    if len(ticks) < 2:
        return 2
    step = ticks[1] - ticks[0]
    return min(2, max(0, -math.floor(math.log10(step) + 1e-9)))


def _limit_text(d: Distribution) -> str:
    if d.mixed_limits:
        return "limits differ: slack shown"
    if d.low_ms is not None and d.high_ms is not None:
        return f"{_fmt(d.low_ms)}..{_fmt(d.high_ms)} ms"
    if d.high_ms is not None:
        return f"≤ {_fmt(d.high_ms)} ms"
    return f"≥ {_fmt(d.low_ms or 0.0)} ms"


def strip(r: RequirementResult, f: Finding, count: int) -> str:
    """One rule's strip: the allowed side, the limit, the uncertainty band, a tick each."""
    d = f.distribution
    assert d is not None
    u = _uncertainty(f, d)
    if d.mixed_limits:
        values, edges, unit = d.slack_ms, [0.0], "slack to the limit"
        inside = [(0.0, None)]  # positive slack is inside
    else:
        values = d.values_ms
        edges = [e for e in (d.low_ms, d.high_ms) if e is not None]
        unit = "measured"
        inside = [(d.low_ms, d.high_ms)]
    points = [*values, *edges, *(e - u for e in edges), *(e + u for e in edges)]
    lo, hi = min(points), max(points)
    pad = max((hi - lo) * 0.08, 0.5)
    lo, hi = lo - pad, hi + pad

    def x(ms: float) -> float:
        return LABEL + (ms - lo) / (hi - lo) * PLOT

    top, base = 6, 30
    parts = []
    for a, b in inside:  # the allowed side, pale green; the rest of the axis pale red
        xa, xb = x(lo if a is None else max(a, lo)), x(hi if b is None else min(b, hi))
        parts.append(f'<rect x="{LABEL}" y="{top}" width="{PLOT}" height="{base - top}" '
                     'fill="#fde8e8"/>')  # fmt: skip
        parts.append(f'<rect x="{xa:.1f}" y="{top}" width="{max(xb - xa, 0):.1f}" '
                     f'height="{base - top}" fill="#e6f4e6"/>')  # fmt: skip
    for e in edges:
        if u > 0:
            parts.append(f'<rect class="sdi12-band" x="{x(e - u):.1f}" y="{top}" '
                         f'width="{x(e + u) - x(e - u):.1f}" height="{base - top}" '
                         'fill="#f4d35e" fill-opacity="0.55"><title>± '
                         f'{u:.2f} ms: the run\'s measured uncertainty</title></rect>')  # fmt: skip
        parts.append(f'<line class="sdi12-limit" x1="{x(e):.1f}" y1="{top - 3}" x2="{x(e):.1f}" '
                     f'y2="{base + 3}" stroke="#222" stroke-width="2"><title>limit {_fmt(e)} ms'
                     '</title></line>')  # fmt: skip
    width = 2 if len(values) <= 20 else 1
    for v in values:
        parts.append(f'<line class="sdi12-tick" x1="{x(v):.1f}" y1="{top + 3}" x2="{x(v):.1f}" '
                     f'y2="{base - 3}" stroke="#1f4e9c" stroke-width="{width}" '
                     'stroke-opacity="0.7"/>')  # fmt: skip
    ticks = nice_ticks(lo, hi)
    places = _places(ticks)
    for t in ticks:
        parts.append(f'<text x="{x(t):.1f}" y="{base + 12}" font-size="9" text-anchor="middle" '
                     f'fill="#555">{t:.{places}f}</text>')  # fmt: skip
    rid = escape(r.requirement.id)
    verdict = escape(str(r.verdict))
    what = escape(r.requirement.statement)
    in_u = d.margin_in_uncertainty(f.uncertainty_ms)
    margin = f"margin {_fmt(d.margin_ms)} ms" + (f" = {in_u:g} u" if in_u is not None else "")
    # Three short lines, not two long ones: "margin -4.60 ms = -0.30 u · ±15.34 ms" ran past
    # the strip's right edge in 10 px type on a bench link's run.
    figures = (f"n={count} · {_fmt(d.min_ms)} / {_fmt(d.median_ms)} / {_fmt(d.max_ms)} ms",
               margin,
               f"±{u:.2f} ms" + (f" · {d.set_aside} set aside" if d.set_aside else ""))  # fmt: skip
    return (
        f'<svg class="sdi12-strip" data-requirement="{rid}" width="{WIDTH}" height="{ROW}" '
        f'viewBox="0 0 {WIDTH} {ROW}" role="img" aria-label="{rid} {unit}">'
        f"<title>{rid}: {what}</title>"
        f'<text x="0" y="17" font-size="12" font-weight="bold">{rid}</text>'
        f'<text x="0" y="31" font-size="10" fill="{_COLOUR.get(verdict, "#444")}">{verdict}'
        f'<tspan fill="#444"> · {_limit_text(d)}</tspan></text>'
        + "".join(parts)
        + "".join(
            f'<text x="{WIDTH - FIGURES + 8}" y="{y}" font-size="10">{line}</text>'
            for y, line in zip((13, 26, 39), figures, strict=True)
        )
        + "</svg>"
    )


def margins_html(results: list[RequirementResult]) -> str:
    """The report's "Timing margins" section (empty when no timed rule was measured)."""
    rows = timed(results)
    if not rows:
        return ""
    return (
        '<div id="sdi12-margins"><h3>Timing margins</h3>'
        "<p>Every measurement a tick (blue), the limit a black line, green the allowed side; "
        "yellow the run's measured uncertainty around the limit, where the tool cannot tell. "
        "Right: count, min / median / max, and the smallest margin to the limit in ms and in "
        "uncertainties (u).</p>" + "".join(strip(r, f, n) for r, f, n in rows) + "</div>"
    )
