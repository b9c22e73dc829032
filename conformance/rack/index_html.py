"""The rack's ``index.html``: one self-contained page (no script, no external style), a row
per DUT with its name, port, identification and serial, verdict, counts, exit status and a
link to its own report.html."""

from __future__ import annotations

from html import escape
from pathlib import Path
from typing import Any

from ..atomic import atomic_path
from .summary import verdict_text

_STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse}th,td{border:1px solid #ccc;padding:.3em .6em;text-align:left}
th{background:#f3f3f3}.code-0{background:#e6f4e6}.code-1{background:#fde2e2}
.code-2,.code-3,.code-4,.code-5{background:#fff3cd}code{font-size:90%}
.rid{font-family:monospace;font-size:90%}
"""
_COUNT_KEYS = ("PASS", "FAIL", "WARN", "INCONCLUSIVE", "N/A", "ERROR")


def _counts(counts: dict[str, int] | None) -> str:
    if not counts:
        return ""
    return ", ".join(f"{counts[k]} {k}" for k in _COUNT_KEYS if counts.get(k))


def _report_link(row: dict[str, Any], rack_dir: Path) -> str:
    folder = row["folder"]
    if folder and (rack_dir / folder / "report.html").is_file():
        return f'<a href="{escape(folder)}/report.html">{escape(folder)}/</a>'
    return escape(folder or "(no report)")


def _row(row: dict[str, Any], rack_dir: Path) -> str:
    ident = row["identification"] or "(no identification)"
    problems = "<br>".join(escape(e) for e in row["errors"])
    cells = (
        escape(row["name"]),
        f"<code>{escape(row['port'])}</code>",
        escape(ident),
        escape(row["serial"] or ""),
        escape(verdict_text(row))
        + "".join(f'<br><span class="rid">{escape(r)}</span>' for r in row.get("failed", [])),
        escape(_counts(row["counts"])),
        f"{row['exit_code']} ({escape(row['meaning'])})",
        _report_link(row, rack_dir),
        problems,
    )
    tds = "".join(f"<td>{c}</td>" for c in cells)
    return f'<tr class="code-{row["exit_code"]}">{tds}</tr>'


def write_index(document: dict[str, Any], rack_dir: Path) -> Path:
    """``rack_dir/index.html`` from rack.json's document."""
    rack, rows = document["rack"], document["duts"]
    head = ("DUT", "port", "identification", "serial", "verdict", "counts", "exit",
            "report", "notes")  # fmt: skip
    state = "complete" if rack["complete"] else "INCOMPLETE"
    if rack.get("interrupted"):
        state += " (interrupted)"
    page = (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8">'
        f"<title>sdi12-conform rack: {escape(rack['meaning'])}</title>"
        f"<style>{_STYLE}</style></head><body>\n"
        f"<h1>Rack of {len(rows)} DUTs: exit {rack['exit_code']} ({escape(rack['meaning'])})</h1>\n"
        f"<p>{escape(state)}; started {escape(str(rack.get('started')))}, "
        f"{rack.get('wall_s')} s wall; the exit status is the worst DUT's, worst first: "
        f"{' &gt; '.join(str(c) for c in rack['worst_first'])}. "
        '<a href="rack.json">rack.json</a>, <a href="junit.xml">junit.xml</a></p>\n'
        "<table><thead><tr>" + "".join(f"<th>{h}</th>" for h in head) + "</tr></thead>\n"
        "<tbody>\n" + "\n".join(_row(r, rack_dir) for r in rows) + "\n</tbody></table>\n"
        "</body></html>\n"
    )
    path = rack_dir / "index.html"
    with atomic_path(path) as tmp:
        tmp.write_text(page, encoding="utf-8")
    return path
