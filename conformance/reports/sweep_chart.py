"""The recorder tolerance sweeps (``--sweep``) in the reports: verdicts.json's ``"sweeps"``
block and the report.html section drawn from it.

Kept in a module of its own so that :mod:`.html` and :mod:`.verdicts_json` need one line
each. The section is drawn from the same JSON the file carries (one mark per step: a filled
dot where the recorder coped, a cross where it did not; the standard's limit as a dashed
line), so the picture can never disagree with the data. The sweep is informational: nothing
here touches a verdict. Every text goes through :func:`html.escape` (the recorder's evidence
may quote what a device sent, design.md 7).
"""

from __future__ import annotations

from html import escape
from typing import Any

#: Plot geometry (px): the strip's width, margins, and the row of marks.
WIDTH, LEFT, RIGHT = 720, 16, 24
HEIGHT, MARK_Y = 96, 40
AXIS_Y = 64
COPED, GAVE_UP, LIMIT = "#2e7d32", "#c62828", "#1565c0"
#: How a step coped, as the mark's inner letter (first try shows as a plain dot).
HOW_LETTER = {"after a retry": "r", "after a new break": "b"}


def sweeps_block(run: Any) -> dict[str, Any]:
    """``{"sweeps": [...]}`` for verdicts.json when ``--sweep`` was given, else ``{}`` (a
    run without it writes the file exactly as before: the key is absent)."""
    sweeps = getattr(run, "sweeps", None)
    return {} if sweeps is None else {"sweeps": [s.to_json() for s in sweeps]}


def summary_lines(data: dict[str, Any]) -> list[str]:
    """One console line per sweep in verdicts.json ``data`` (none without ``--sweep``)."""
    lines = []
    for sweep in data.get("sweeps", []):
        up, fail = sweep["copes_up_to_ms"], sweep.get("first_failure_ms")
        copes = "copes at no step" if up is None else f"copes up to {up:.2f} ms"
        stops = f", gives up at {fail:.2f} ms" if fail is not None else ", at every step"
        if not sweep["steps"]:
            copes, stops = "no step ran", ""
        line = f"{sweep['kind']} sweep: {copes}{stops} (limit {sweep['limit_ms']:.2f} ms)"
        if sweep["flag"]:
            line += f"; FLAG: {sweep['flag']}"
        if sweep.get("stopped"):
            line += f"; stopped: {sweep['stopped']}"
        lines.append(line)
    return lines


def section(run: Any) -> str:
    """The report.html section for the run's sweeps ("" without ``--sweep``)."""
    block = sweeps_block(run)
    if not block:
        return ""
    return render(block["sweeps"])


def render(sweeps: list[dict[str, Any]]) -> str:
    """The section for verdicts.json's ``"sweeps"`` list."""
    parts = [
        '<div class="sdi12" id="sdi12-sweeps"><h2>Tolerance sweeps (informational)</h2>',
        "<p>One short job (aM!, then its data) per step on a played sensor made slower step by "
        "step. A sweep never changes a verdict; a recorder that gives up inside the "
        "standard's limit is flagged.</p>",
    ]
    if not sweeps:
        parts.append("<p>No sweep ran (the run did not complete).</p>")
    for sweep in sweeps:
        parts.append(_one(sweep))
    parts.append("</div>")
    return "".join(parts)


def _one(sweep: dict[str, Any]) -> str:
    kind = escape(str(sweep["kind"]))
    limit = float(sweep["limit_ms"])
    rids = ", ".join(escape(r) for r in sweep["requirements"])
    up = sweep["copes_up_to_ms"]
    copes = "copes at no step" if up is None else f"copes up to {up:.2f} ms"
    if not sweep["steps"]:
        copes = "no step ran"
    head = (
        f'<h3 id="sdi12-sweep-{kind}">{kind} sweep: {copes} '
        f"(standard's limit {limit:.2f} ms, {rids})</h3>"
        f"<p>{escape(str(sweep.get('measures', '')))}.</p>"
    )
    flag = sweep["flag"]
    flagged = (
        f'<p class="sdi12-sweep-flag" style="color:{GAVE_UP}"><b>FLAG:</b> {escape(flag)}</p>'
        if flag
        else ""
    )
    stopped = sweep.get("stopped")
    if stopped:
        flagged += f"<p><b>Sweep stopped:</b> {escape(stopped)}</p>"
    return head + flagged + strip_svg(sweep) + _table(sweep)


def strip_svg(sweep: dict[str, Any]) -> str:
    """One mark per step along the effective time, and the limit as a dashed line."""
    steps = sweep["steps"]
    limit = float(sweep["limit_ms"])
    top = max([limit, *(float(s["effective_ms"]) for s in steps)]) or 1.0
    scale = (WIDTH - LEFT - RIGHT) / top

    def x(ms: float) -> float:
        return round(LEFT + ms * scale, 1)

    kind = escape(str(sweep["kind"]))
    out = [
        f'<svg class="sdi12-sweep" data-kind="{kind}" xmlns="http://www.w3.org/2000/svg" '
        f'width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" '
        'font-family="sans-serif" font-size="11">',
        f'<rect x="{LEFT}" y="{MARK_Y - 16}" width="{x(limit) - LEFT}" height="32" '
        'fill="#e3f2fd"><title>what the standard makes a recorder cope with</title></rect>',
        f'<line class="sdi12-sweep-limit" x1="{x(limit)}" y1="12" x2="{x(limit)}" '
        f'y2="{AXIS_Y}" stroke="{LIMIT}" stroke-width="2" stroke-dasharray="5,3"/>',
        f'<text x="{x(limit)}" y="10" fill="{LIMIT}" text-anchor="middle">'
        f"limit {limit:.2f} ms</text>",
        f'<line x1="{LEFT}" y1="{AXIS_Y}" x2="{WIDTH - RIGHT}" y2="{AXIS_Y}" stroke="#555"/>',
    ]
    ticks = sorted({0.0, top, *(float(s["effective_ms"]) for s in steps[::4])})
    for ms in ticks:
        out.append(
            f'<line x1="{x(ms)}" y1="{AXIS_Y}" x2="{x(ms)}" y2="{AXIS_Y + 4}" stroke="#555"/>'
            f'<text x="{x(ms)}" y="{AXIS_Y + 16}" text-anchor="middle">{ms:g}</text>'
        )
    out.append(
        f'<text x="{WIDTH - RIGHT}" y="{AXIS_Y + 30}" text-anchor="end">'
        f"{escape(str(sweep['kind']))} time, ms (dot: coped, r: after a retry, b: after a new "
        "break; cross: gave up)</text>"
    )
    for s in steps:
        out.append(_mark(x(float(s["effective_ms"])), s))
    out.append("</svg>")
    return "".join(out)


def _mark(cx: float, step: dict[str, Any]) -> str:
    tip = escape(
        f"{step['effective_ms']:g} ms ({step['extra_ms']:g} ms extra): "
        + (f"coped, {step['how']}" if step["coped"] else "gave up")
        + f"; {step['evidence']}"
    )
    if step["coped"]:
        letter = HOW_LETTER.get(str(step["how"]), "")
        inner = (
            f'<text x="{cx}" y="{MARK_Y + 4}" fill="#fff" font-size="10" '
            f'text-anchor="middle">{letter}</text>'
            if letter
            else ""
        )
        return (
            f'<g class="sdi12-sweep-step coped"><title>{tip}</title>'
            f'<circle cx="{cx}" cy="{MARK_Y}" r="6" fill="{COPED}"/>{inner}</g>'
        )
    d = 5
    return (
        f'<g class="sdi12-sweep-step gave-up" stroke="{GAVE_UP}" stroke-width="2.5">'
        f"<title>{tip}</title>"
        f'<line x1="{cx - d}" y1="{MARK_Y - d}" x2="{cx + d}" y2="{MARK_Y + d}"/>'
        f'<line x1="{cx - d}" y1="{MARK_Y + d}" x2="{cx + d}" y2="{MARK_Y - d}"/></g>'
    )


def _table(sweep: dict[str, Any]) -> str:
    limit = float(sweep["limit_ms"])
    rows = []
    for s in sweep["steps"]:
        inside = "inside" if float(s["effective_ms"]) <= limit + 1e-9 else "beyond"
        coped = f"coped, {s['how']}" if s["coped"] else "GAVE UP"
        rows.append(
            f'<tr class="{"coped" if s["coped"] else "gave-up"}"><td>{s["extra_ms"]:g}</td>'
            f"<td>{s['effective_ms']:g}</td><td>{inside}</td><td>{escape(coped)}</td>"
            f"<td>{escape(str(s['evidence']))}</td></tr>"
        )
    return (
        '<details><summary>Steps</summary><table class="sdi12"><thead><tr><th>extra ms</th>'
        "<th>effective ms</th><th>limit</th><th>result</th><th>evidence</th></tr></thead>"
        f"<tbody>{''.join(rows)}</tbody></table></details>"
    )
