"""The test plan (issue 24, contract ``sdi12-conform/plan/1``): what a run will do, written
before the bus is touched, as h2spec and the qualification tools of other buses give it.

Built from a dry run: the whole suite in virtual time against a simulated sensor that plays
the declaration (:mod:`conformance.emulator.declared`), so every case's commands and bus time
come from the very code that will run, never from a second description of it that could lag.
The plan lists, per case, its requirements, the preconditions it checks on the wire, what it
will send, what would make it N/A for this declaration, and its bus time; and the run's
expected bus time, which on a real link is the floor under the wall time (host latency and the
link's turnarounds come on top).

Pure functions over the dry run's ``verdicts.json``; rendered as JSON, Markdown and HTML.
"""

from __future__ import annotations

import json
from html import escape
from pathlib import Path
from typing import Any

from ..catalog import for_role
from ..run import TOOL_IDENTITY

SCHEMA = "sdi12-conform/plan/1"
#: what the commands a case puts on the bus are, by role
SENDS = {"sensor": "the tool sends", "recorder": "the recorder is to send"}
#: where a planned run keeps its plan, beside verdicts.json
PLAN_FILE = "plan.json"
DRY_RUN = {
    "sensor": "the suite in virtual time against a simulated sensor playing the declaration",
    "recorder": "the suite in virtual time with the golden recorder as the recorder under test",
}


def _first_line(text: str) -> str:
    lines = text.strip().splitlines()
    return lines[0] if lines else ""


def _na_reasons(dry: dict[str, Any]) -> dict[str, list[str]]:
    """case id -> why it came out N/A on the declared sensor (its N/A findings' details)."""
    reasons: dict[str, list[str]] = {}
    for r in dry.get("requirements", []):
        for f in r.get("findings", []):
            if f.get("verdict") == "N/A" and f.get("test"):
                seen = reasons.setdefault(f["test"], [])
                if f["detail"] not in seen:
                    seen.append(f["detail"])
    return reasons


def build_plan(
    dry: dict[str, Any],
    *,
    role: str,
    dry_port: str,
    declaration: str | None,
    assumptions: list[str],
    selection: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The plan from the dry run's verdicts.json (``dry``)."""
    na = _na_reasons(dry)
    cases = []
    for t in dry.get("tests", []):
        verdict = t.get("verdict")
        cases.append(
            {
                "id": t["id"],
                "title": _first_line(t.get("description") or ""),
                "requirements": list(t.get("requirements", [])),
                "preconditions": sorted(t.get("preconditions", {})),
                "sends": list(t.get("sent", [])),
                "expected_bus_s": t.get("bus_s"),
                "not_applicable": ("; ".join(na.get(t["id"], [])) or "N/A")
                if verdict == "N/A"
                else None,
            }
        )
    judged = sorted(
        {rid for c in cases if c["not_applicable"] is None for rid in c["requirements"]}
    )
    catalog = for_role(role)
    untestable = sorted(r.id for r in catalog if not r.testable(role))
    bus = dry.get("run", {}).get("bus", {})
    return {
        "schema": SCHEMA,
        "tool": dict(TOOL_IDENTITY),
        "role": role,
        "sdi12_version": dry.get("dut", {}).get("sdi12_version"),
        "declaration": declaration,
        "assumptions": list(assumptions),
        "selection": selection,
        "dry_run": {"port": dry_port, "how": DRY_RUN[role]},
        "expected_bus_s": bus.get("link_clock_s"),
        "bus_lower_bound_s": bus.get("bus_lower_bound_s"),
        "cases": cases,
        "requirements": {
            "catalog": len(catalog),
            "judged": judged,
            "not_applicable": sorted(
                {rid for c in cases if c["not_applicable"] for rid in c["requirements"]}
                - set(judged)
            ),
            "untestable": untestable,
        },
    }


def duration(seconds: float | None) -> str:
    if seconds is None:
        return "—"
    if seconds >= 60:
        return f"{seconds / 60:.1f} min"
    return f"{seconds:.1f} s"


def _sends(sends: list[dict[str, Any]], most: int = 8) -> str:
    shown = [s["command"] + (f" ×{s['times']}" if s["times"] > 1 else "") for s in sends[:most]]
    if len(sends) > most:
        shown.append(f"+{len(sends) - most} more")
    return ", ".join(shown) if shown else "nothing of its own (judges what others sent)"


def plan_markdown(plan: dict[str, Any]) -> str:
    reqs = plan["requirements"]
    lines = [
        f"# SDI-12 test plan ({plan['role']} role)",
        "",
        f"- Tool: {plan['tool']['name']} {plan['tool']['version']}",
        f"- Declaration: {plan['declaration'] or 'none (the tool discovers what it can)'}",
        f"- SDI-12 version: {plan['sdi12_version'] or 'unknown'}",
        f"- Expected bus time: {duration(plan['expected_bus_s'])} "
        "(a real link adds its host and turnaround delays)",
        f"- Cases: {len(plan['cases'])}; requirements judged {len(reqs['judged'])}, N/A for "
        f"this declaration {len(reqs['not_applicable'])}, untestable by this tool "
        f"{len(reqs['untestable'])}, of {reqs['catalog']}",
        f"- Dry run: `{plan['dry_run']['port']}`: {plan['dry_run']['how']}",
    ]
    for a in plan["assumptions"]:
        lines.append(f"- Assumed: {a}")
    lines += [
        "",
        f"| case | requirements | preconditions | {SENDS[plan['role']]} | bus time "
        "| N/A for this declaration |",
        "|---|---|---|---|---|---|",
    ]
    for c in plan["cases"]:
        name = c["id"].split("::")[-1]
        cells = [
            f"`{name}` {c['title']}",
            " ".join(c["requirements"]),
            ", ".join(c["preconditions"]) or "—",
            _sends(c["sends"]),
            duration(c["expected_bus_s"]),
            c["not_applicable"] or "",
        ]
        lines.append("| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |")
    return "\n".join(lines) + "\n"


PLAN_STYLE = (
    "<style>.sdi12-plan{border-collapse:collapse;font-size:12px}"
    ".sdi12-plan td,.sdi12-plan th{border:1px solid #ccc;padding:3px 6px;vertical-align:top}"
    ".sdi12-plan tr.na td{color:#777}.sdi12-plan code{font-size:11px}</style>"
)


def plan_table(plan: dict[str, Any], judged: dict[str, dict[str, Any]] | None = None) -> str:
    """The plan's cases as an HTML table; with ``judged`` (case id -> the run's tests entry)
    each row also shows what the run did: its verdict and its time on the bus."""
    head = "<tr><th>case</th><th>requirements</th><th>preconditions</th>"
    head += f"<th>{SENDS[plan['role']]}</th>"
    head += "<th>planned bus time</th><th>N/A for this declaration</th>"
    head += "<th>judged</th><th>bus time</th></tr>" if judged is not None else "</tr>"
    rows = []
    for c in plan["cases"]:
        cls = ' class="na"' if c["not_applicable"] else ""
        row = (
            f"<tr{cls}><td><code>{escape(c['id'].split('::')[-1])}</code><br>"
            f"{escape(c['title'])}</td><td>{escape(' '.join(c['requirements']))}</td>"
            f"<td>{escape(', '.join(c['preconditions']) or '—')}</td>"
            f"<td>{escape(_sends(c['sends']))}</td><td>{duration(c['expected_bus_s'])}</td>"
            f"<td>{escape(c['not_applicable'] or '')}</td>"
        )
        if judged is not None:
            done = judged.get(c["id"])
            row += (
                f"<td>{escape(done['verdict'])}</td><td>{duration(done.get('bus_s'))}</td>"
                if done
                else "<td>not run</td><td>—</td>"
            )
        rows.append(row + "</tr>")
    return f'<table class="sdi12-plan">{head}{"".join(rows)}</table>'


def plan_html(plan: dict[str, Any]) -> str:
    """A self-contained page: the plan a certifier files before the run."""
    items = "".join(
        f"<li>{escape(line[2:])}</li>"
        for line in plan_markdown(plan).splitlines()[2:]
        if line.startswith("- ")
    )
    title = f"SDI-12 test plan ({escape(plan['role'])} role)"
    return (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{title}</title>"
        f"{PLAN_STYLE}</head><body style='font-family:sans-serif'><h1>{title}</h1>"
        f"<ul>{items}</ul>{plan_table(plan)}</body></html>"
    )


def read_plan(directory: Path) -> dict[str, Any] | None:
    """The plan a run folder holds (None without one, or with one that is not a plan)."""
    path = Path(directory) / PLAN_FILE
    try:
        plan = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return plan if isinstance(plan, dict) and plan.get("schema") == SCHEMA else None


def write_plan(directory: Path, plan: dict[str, Any]) -> Path:
    path = Path(directory) / PLAN_FILE
    path.write_text(json.dumps(plan, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return path


def plan_section(plan: dict[str, Any] | None, judged: dict[str, dict[str, Any]]) -> str:
    """The run report's "Test plan" block: what was planned beside what was judged."""
    if plan is None:
        return ""
    took = sum(j.get("bus_s") or 0.0 for j in judged.values())
    return (
        '<details id="sdi12-plan"><summary><b>Test plan</b>: '
        f"{len(plan['cases'])} cases planned, expected bus time "
        f"{duration(plan.get('expected_bus_s'))}; this run: {len(judged)} cases, "
        f"{duration(took)} on the bus (plan.json beside this report)</summary>"
        f"{PLAN_STYLE}{plan_table(plan, judged)}</details>"
    )
