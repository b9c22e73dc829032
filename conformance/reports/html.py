"""Everything sdi12-conform adds to the pytest-html report.

The header (DUT identity, link, tool), the overall verdict banner, the sortable and filterable
requirements table, and per case the expectation, findings and wire transcript. Everything that
came from the DUT goes through :func:`html.escape` (design.md 7: the device is untrusted).
"""

from __future__ import annotations

from html import escape
from typing import Any

import pytest

from ..results import COMPLIANT, NON_COMPLIANT, CaseRecord, counts
from ..run import TOOL, ConformanceRun
from ..transcript import TOOL as TOOL_ORIGIN
from ..transcript import Event, EventKind
from ..transcript import escape as wire_escape
from .verdicts_json import dut_block

STYLE = """
<style>
.sdi12-banner{font:bold 28px sans-serif;padding:14px 20px;border-radius:6px;margin:10px 0;
  color:#fff}
.sdi12-banner.ok{background:#2e7d32}.sdi12-banner.bad{background:#c62828}
.sdi12-banner.incomplete{background:#ef6c00}
.sdi12-banner small{display:block;font:14px sans-serif;margin-top:4px}
table.sdi12{border-collapse:collapse;margin:8px 0;font:13px sans-serif}
table.sdi12 td,table.sdi12 th{border:1px solid #ccc;padding:3px 6px;vertical-align:top;
  text-align:left}
table.sdi12 th{background:#eee;cursor:pointer}
.v-PASS{color:#2e7d32;font-weight:bold}.v-FAIL{color:#c62828;font-weight:bold}
.v-WARN{color:#b26a00;font-weight:bold}.v-INCONCLUSIVE{color:#6a1b9a;font-weight:bold}
.v-NA{color:#666}.v-ERROR{color:#fff;background:#c62828;font-weight:bold}
.sdi12-wire{font:12px monospace;white-space:pre}
.sdi12-wire .tool{color:#1565c0}.sdi12-wire .dut{color:#2e7d32}.sdi12-wire .brk{color:#b26a00}
</style>
"""

SCRIPT = """
<script>
(function(){
  var t=document.getElementById('sdi12-requirements'); if(!t) return;
  var f=document.getElementById('sdi12-filter');
  f.addEventListener('input',function(){var q=f.value.toLowerCase();
    t.querySelectorAll('tbody tr').forEach(function(r){
      r.style.display=r.textContent.toLowerCase().indexOf(q)>=0?'':'none';});});
  t.querySelectorAll('th').forEach(function(th,i){th.addEventListener('click',function(){
    var rows=Array.prototype.slice.call(t.querySelectorAll('tbody tr'));
    var asc=th.dataset.asc!=='1'; th.dataset.asc=asc?'1':'0';
    rows.sort(function(a,b){var x=a.cells[i].textContent,y=b.cells[i].textContent;
      var o={numeric:true};
      return asc?x.localeCompare(y,undefined,o):y.localeCompare(x,undefined,o);});
    rows.forEach(function(r){t.tBodies[0].appendChild(r);});});});
})();
</script>
"""


def verdict_class(verdict: str) -> str:
    return "v-NA" if verdict == "N/A" else f"v-{verdict}"


def banner(run: ConformanceRun) -> str:
    verdict = run.verdict or "INCOMPLETE"
    css = {COMPLIANT: "ok", NON_COMPLIANT: "bad"}.get(verdict, "incomplete")
    tally = counts(run.results or [])
    line = ", ".join(f"{n} {k}" for k, n in tally.items() if n)
    reason = f" — {escape(run.stop_reason)}" if run.stop_reason else ""
    return (
        f'<div class="sdi12-banner {css}" id="sdi12-verdict">{escape(verdict)}'
        f"<small>{escape(line)} requirements{reason}</small></div>"
    )


def header(run: ConformanceRun) -> str:
    dut = dut_block(run)
    link = run.link_description()
    rows = [
        ("Tool", f"{TOOL['name']} {TOOL['version']}"),
        ("Role", run.options.role),
        ("Port", run.options.port),
        (
            "Link",
            f"{link['kind']}, breaks: {link['can_break']}, "
            f"timing uncertainty ±{link['timing_uncertainty_ms']} ms",
        ),
        ("Started / finished", f"{run.started} / {run.finished}"),
        ("DUT address", dut["address"]),
        ("Identification (aI!)", wire_escape(dut["identification"] or "(none)")),
        ("Claimed SDI-12 version", dut["sdi12_version"]),
        ("Vendor / model / firmware", f"{dut['vendor']} / {dut['model']} / {dut['firmware']}"),
        ("Declaration", dut["declaration"] or "none (features discovered)"),
        ("Assumptions", "; ".join(dut["assumptions"]) or "none"),
        ("Strict (SHOULD as MUST)", str(run.options.strict)),
        ("Complete", str(run.complete)),
    ]
    body = "".join(f"<tr><th>{escape(k)}</th><td>{escape(str(v))}</td></tr>" for k, v in rows)
    return f'<table class="sdi12" id="sdi12-header">{body}</table>'


def requirements_table(run: ConformanceRun) -> str:
    rows = []
    for r in run.results or []:
        req = r.requirement
        tests = "<br>".join(escape(t.split("::")[-1]) for t in r.tests) or "—"
        rows.append(
            f"<tr><td>{escape(req.id)}</td><td>{escape(req.clause)}</td>"
            f"<td>{escape(req.level)}</td>"
            f'<td class="{verdict_class(str(r.verdict))}">{escape(str(r.verdict))}</td>'
            f"<td>{escape(req.statement)}</td><td>{escape(r.one_line)}</td><td>{tests}</td></tr>"
        )
    return (
        "<h2>Requirements</h2>"
        '<p>Filter: <input id="sdi12-filter" placeholder="ID, verdict, text..."> '
        "(click a column heading to sort)</p>"
        '<table class="sdi12" id="sdi12-requirements"><thead><tr><th>ID</th><th>Clause</th>'
        "<th>Level</th><th>Verdict</th><th>Requirement</th><th>Evidence</th><th>Tests</th>"
        f"</tr></thead><tbody>{''.join(rows)}</tbody></table>"
    )


def transcript_html(label: str, events: list[Event]) -> str:
    if not events:
        return f"<p><b>{escape(label)}</b>: no bus events</p>"
    t0 = events[0].start
    lines = []
    for group in _group(events):
        first = group[0]
        at = f"{(first.start - t0) * 1e3:9.2f} ms"
        if first.kind is EventKind.BREAK:
            lines.append(f'<span class="brk">{at}  BREAK {first.duration * 1e3:.2f} ms</span>')
        elif first.kind is EventKind.NOTE:
            lines.append(f"{at}  note  {escape(first.text)}")
        else:
            who = "tool" if first.origin == TOOL_ORIGIN else "dut"
            arrow = "→" if who == "tool" else "←"
            text = wire_escape(bytes(e.char7 for e in group))
            bad = sum(1 for e in group if not e.parity_ok)
            parity = f"  [{bad} parity error(s)]" if bad else ""
            lines.append(
                f'<span class="{who}">{at}  {arrow} {who:4} {escape(text)}'
                f"  ({len(group)} chars, ends {(group[-1].end - t0) * 1e3:.2f} ms){parity}</span>"
            )
    return f'<p><b>{escape(label)}</b></p><div class="sdi12-wire">' + "\n".join(lines) + "</div>"


def _group(events: list[Event]) -> list[list[Event]]:
    """Runs of characters from one side with gaps under two frame times form one line."""
    groups: list[list[Event]] = []
    for e in events:
        if (
            groups
            and e.kind is EventKind.CHAR
            and groups[-1][-1].kind is EventKind.CHAR
            and groups[-1][-1].origin == e.origin
            and e.start - groups[-1][-1].end < 0.0167
        ):
            groups[-1].append(e)
        else:
            groups.append([e])
    return groups


def case_html(record: CaseRecord) -> str:
    parts = [STYLE]
    if record.description:
        parts.append(f"<p><b>Case</b>: {escape(record.description)}</p>")
    if record.expectation:
        parts.append(f"<p><b>Expectation</b>: {escape(record.expectation)}</p>")
    rows = "".join(
        f'<tr><td>{escape(f.requirement)}</td><td class="{verdict_class(str(f.verdict))}">'
        f"{escape(str(f.verdict))}</td><td>{escape(f.detail)}"
        + (f"<br><i>{escape('; '.join(f.evidence))}</i>" if f.evidence else "")
        + (f" <i>(decision {escape(f.decision)})</i>" if f.decision else "")
        + "</td></tr>"
        for f in record.findings
    )
    parts.append(
        '<table class="sdi12"><tr><th>Requirement</th><th>Verdict</th><th>Observation</th></tr>'
        f"{rows}</table>"
    )
    for label, events in record.evidence:
        parts.append(transcript_html(label, events))
    return "".join(parts)


class HtmlReportPlugin:
    """pytest-html hooks, bound to the run whose verdicts they show."""

    def __init__(self, run: ConformanceRun) -> None:
        self.run = run

    def pytest_html_report_title(self, report: Any) -> None:
        report.title = f"SDI-12 conformance report ({self.run.options.role})"

    def pytest_html_results_summary(
        self, prefix: list[str], summary: list[str], postfix: list[str], session: Any
    ) -> None:
        if self.run.results is None:
            return
        prefix.extend([STYLE, banner(self.run), header(self.run)])
        postfix.extend([requirements_table(self.run), SCRIPT])

    def pytest_html_results_table_header(self, cells: list[str]) -> None:
        cells.insert(1, '<th class="sortable" data-column-type="verdict">Verdict</th>')
        cells.insert(2, "<th>Requirements</th>")

    def pytest_html_results_table_row(self, report: Any, cells: list[str]) -> None:
        verdict = getattr(report, "sdi12_verdict", "")
        reqs = " ".join(getattr(report, "sdi12_requirements", ()))
        cells.insert(1, f'<td class="col-verdict {verdict_class(verdict)}">{escape(verdict)}</td>')
        cells.insert(2, f"<td>{escape(reqs)}</td>")

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_makereport(self, item: Any, call: Any):
        report = yield
        from ..plugin import CASE

        record = item.stash.get(CASE, None)
        if record is not None and report.when == "call":
            from pytest_html import extras

            report.extras = [*getattr(report, "extras", []), extras.html(case_html(record))]
        return report
