"""report.html as a certifier sees it: rendered by headless Chromium, not read as text.

A clean and a faulty run are rendered at a laptop's viewport. The page must load without a
console error or exception, show the overall verdict without scrolling, show the requirements
table with every requirement, and let the table be filtered and sorted. Screenshots go to
``reports/screenshots/`` (git ignores it) for a person to look at.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.support.report_browser import SCREENSHOTS, Chromium, require_chromium

# Drives headless Chromium.
pytestmark = pytest.mark.browser

RUNS = {
    "clean": ("sim", 0),
    "faulty": ("sim://?faults=no-service-request", 1),
    "late": ("sim://?faults=response-too-late", 1),  # a timing fault: the margins chart
    "long": ("sim://?faults=abort-keeps-old-data", 1),  # 60-character replies as evidence
}
VIEWPORT = (1280, 720)

STATE = """(function(){
  function box(e){ if(!e) return null; var r=e.getBoundingClientRect(), s=getComputedStyle(e);
    return {top:r.top, bottom:r.bottom, width:r.width, height:r.height,
            shown: s.display!=='none' && s.visibility!=='hidden' && r.width>0 && r.height>0}; }
  var banner=document.getElementById('sdi12-verdict');
  var table=document.getElementById('sdi12-requirements');
  return {viewport: innerHeight, banner: box(banner),
          bannerText: banner ? banner.textContent : '',
          table: box(table), rows: table ? table.tBodies[0].rows.length : 0,
          header: (document.getElementById('sdi12-header')||{}).textContent || '',
          cases: document.querySelectorAll('#results-table tbody.results-table-row').length};
})()"""

VISIBLE_ROWS = """[...document.querySelectorAll('#sdi12-requirements tbody tr')]
  .filter(r => r.style.display !== 'none')
  .map(r => ({id: r.cells[0].textContent, verdict: r.cells[3].textContent}))"""


def _run(port: str, out: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "conformance.cli", "--port", port, "--report-dir", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    require_chromium()
    out = {}
    for name, (port, exit_code) in RUNS.items():
        directory = tmp_path_factory.mktemp(name)
        proc = _run(port, directory)
        assert proc.returncode == exit_code, proc.stdout + proc.stderr
        out[name] = directory
    return out


@pytest.fixture(scope="module")
def browser() -> Iterator[Chromium]:
    require_chromium()
    with Chromium(*VIEWPORT) as chromium:
        yield chromium


@pytest.mark.parametrize("name", sorted(RUNS))
def test_report_renders_with_the_verdict_above_the_fold(reports, browser, name):
    directory = reports[name]
    data = json.loads((directory / "verdicts.json").read_text(encoding="utf-8"))
    browser.open(directory / "report.html")
    state = browser.evaluate(STATE)
    shot = browser.screenshot(SCREENSHOTS / f"report-{name}.png")

    assert browser.log.problems == [], browser.log.problems
    assert state["banner"]["shown"], state
    # first thing under the title (pytest-html's environment table must not push it down)
    assert 0 <= state["banner"]["top"] < 0.2 * state["viewport"], state["banner"]
    assert state["banner"]["bottom"] <= state["viewport"], state["banner"]
    assert state["bannerText"].startswith(data["summary"]["verdict"]), state["bannerText"]
    assert data["dut"]["identification"].strip() in state["header"]
    assert f"sdi12-conform {data['tool']['version']}" in state["header"]
    assert state["table"]["shown"]
    assert state["rows"] == len(data["requirements"])
    assert state["cases"] == len(data["tests"])
    assert shot.stat().st_size > 10_000


def test_requirements_table_filters_and_sorts(reports, browser):
    directory = reports["faulty"]
    data = json.loads((directory / "verdicts.json").read_text(encoding="utf-8"))
    browser.open(directory / "report.html")

    browser.evaluate(
        "(function(){var v=document.getElementById('sdi12-verdict-filter'); v.value='FAIL';"
        " v.dispatchEvent(new Event('change'));})()"
    )
    failing = browser.evaluate(VISIBLE_ROWS)
    assert [r["id"] for r in failing] == [
        r["id"] for r in data["requirements"] if r["verdict"] == "FAIL"
    ]
    assert "1 of" in browser.evaluate("document.getElementById('sdi12-shown').textContent")

    browser.evaluate(
        "(function(){var v=document.getElementById('sdi12-verdict-filter'); v.value='';"
        " v.dispatchEvent(new Event('change'));"
        " var f=document.getElementById('sdi12-filter'); f.value='r-7.0-1';"
        " f.dispatchEvent(new Event('input'));})()"
    )
    matching = browser.evaluate(VISIBLE_ROWS)
    assert matching and all(r["id"].startswith("R-7.0-1") for r in matching), matching

    browser.evaluate(
        "(function(){var f=document.getElementById('sdi12-filter'); f.value='';"
        " f.dispatchEvent(new Event('input'));"
        " document.querySelectorAll('#sdi12-requirements thead th')[3].click();})()"
    )
    by_verdict = [r["verdict"] for r in browser.evaluate(VISIBLE_ROWS)]
    severity = ["ERROR", "FAIL", "INCONCLUSIVE", "WARN", "PASS", "N/A"]
    assert by_verdict == sorted(by_verdict, key=severity.index), "verdict sort is by severity"
    assert by_verdict[0] == "FAIL"

    browser.evaluate("document.querySelectorAll('#sdi12-requirements thead th')[0].click()")
    browser.evaluate("document.querySelectorAll('#sdi12-requirements thead th')[0].click()")
    ids = [r["id"] for r in browser.evaluate(VISIBLE_ROWS)]
    assert ids[0] > ids[-1], "a second click sorts descending"

    browser.evaluate("document.querySelector('[data-sdi12-show=\"N/A\"]').click()")
    shown = browser.evaluate(VISIBLE_ROWS)
    assert shown and {r["verdict"] for r in shown} == {"N/A"}
    assert browser.log.problems == []


def test_timing_case_shows_its_diagram(reports, browser):
    """A whole-run timing case attaches no evidence; the report draws the exchange behind
    its worst measurement, and the SVG renders."""
    browser.open(reports["faulty"] / "report.html")
    tbody = (
        "[...document.querySelectorAll('#results-table tbody')]"
        ".find(t => t.id.endsWith('::test_response_start_window'))"
    )
    browser.evaluate(
        f"(function(){{var t={tbody}; if (t.querySelector('.extras-row.hidden'))"
        " t.querySelector('.collapsible td').click();})()"
    )
    svg = browser.evaluate(
        f"(function(){{var s=({tbody}).querySelector('svg.sdi12-timing');"
        " if(!s) return null; var r=s.getBoundingClientRect();"
        " return {w:r.width, h:r.height, text:s.textContent};})()"
    )
    browser.screenshot(SCREENSHOTS / "timing-case.png", element=tbody)
    assert svg is not None, "no timing diagram in the expanded case"
    assert svg["w"] > 300 and svg["h"] > 100
    assert "reply +" in svg["text"] and "break" in svg["text"]
    assert browser.log.problems == []


LEFTOVERS = """(function(){
  function shown(e){ if(!e) return false; var r=e.getBoundingClientRect(), s=getComputedStyle(e);
    return s.display!=='none' && s.visibility!=='hidden' && r.width>0 && r.height>0; }
  var spans=[...document.querySelectorAll('.filters span')].filter(shown).map(s=>s.textContent);
  var logs=[...document.querySelectorAll('#results-table tbody.failed .logwrapper')]
    .filter(l=>l.closest('td').querySelector('.sdi12-case')).filter(shown).length;
  return {environment: shown(document.getElementById('environment-header')),
          filters: spans, logs: logs,
          heading: (document.querySelector('.summary__data h2')||{}).textContent};
})()"""

TARGET = """(function(){ var b=document.querySelector('tbody.sdi12-target'); if(!b) return null;
  var r=b.getBoundingClientRect();
  return {id: b.id, top: r.top, open: !b.querySelector('.extras-row').classList.contains('hidden'),
          case: !!b.querySelector('.sdi12-case')}; })()"""


def test_the_report_is_a_verdict_document_not_a_test_log(reports, browser):
    """No environment table, no '0 Expected failures, 0 Unexpected passes, 0 Reruns', no grey
    log box repeating a case's FAIL line next to the case's own findings."""
    browser.open(reports["faulty"] / "report.html")
    browser.evaluate("document.getElementById('show_all_details').click()")
    state = browser.evaluate(LEFTOVERS)
    assert state["environment"] is False
    assert state["filters"] and not [f for f in state["filters"] if f.startswith("0 ")]
    assert state["logs"] == 0
    assert state["heading"].startswith("Evidence")
    assert browser.log.problems == []


@pytest.mark.parametrize("where", ["#sdi12-attention", "#sdi12-requirements"])
def test_links_open_the_case_that_holds_the_evidence(reports, browser, where):
    browser.open(reports["faulty"] / "report.html")
    name = browser.evaluate(
        f"(function(){{var a=document.querySelector('{where} a[data-sdi12-case]');"
        " a.click(); return a.dataset.sdi12Case;})()"
    )
    browser.evaluate("new Promise(r => setTimeout(r, 200))")
    target = browser.evaluate(TARGET)
    assert target is not None, f"no case opened for {name}"
    assert target["id"].endswith("::" + name) and target["open"] and target["case"]
    assert 0 <= target["top"] < VIEWPORT[1], "the case was scrolled into view"
    browser.screenshot(SCREENSHOTS / f"case-from-{where[1:]}.png")
    assert browser.log.problems == []


DRAWN = """(function(){
  var cells=[...document.querySelectorAll('#results-table tbody.results-table-row td.col-result')];
  function shown(c){return getComputedStyle(c,'::before').content.replace(/^"|"$/g,'');}
  var ids=[...document.querySelectorAll('#results-table .sdi12-rid')];
  var credit=[...document.querySelectorAll('p')].filter(p=>/generated on/.test(p.textContent));
  return {shown: cells.map(shown), text: cells.map(c=>getComputedStyle(c).fontSize),
          count: (document.querySelector('.run-count')||{}).textContent,
          credit: credit.map(p=>p.textContent),
          wrapped: ids.filter(s=>s.getClientRects().length>1).map(s=>s.textContent)};
})()"""


def test_the_cases_table_speaks_verdicts_and_counts_cases(reports, browser):
    """Issue 19: the Result column said "Skipped" for INCONCLUSIVE and N/A, the count said
    "60 tests took" beside 62 cases, the credit was pytest-html's, and a requirement ID
    wrapped inside itself. The screenshot is for a person to look at."""
    browser.open(reports["faulty"] / "report.html")
    browser.evaluate("document.getElementById('results-table').scrollIntoView()")
    browser.screenshot(SCREENSHOTS / "cases-table.png")
    state = browser.evaluate(DRAWN)
    data = json.loads((reports["faulty"] / "verdicts.json").read_text(encoding="utf-8"))
    assert set(state["shown"]) <= {"PASS", "FAIL", "WARN", "INCONCLUSIVE", "N/A", "ERROR"}
    assert {"FAIL", "INCONCLUSIVE", "PASS"} <= set(state["shown"]), state["shown"]
    assert set(state["text"]) == {"0px"}  # pytest's outcome word is not drawn
    assert state["count"].startswith(f"{len(state['shown'])} conformance cases took")
    assert len(state["shown"]) == len(data["tests"])  # every case, skipped-by-pytest ones too
    assert state["credit"] and state["credit"][0].startswith("Report by sdi12-conform ")
    assert state["wrapped"] == []
    assert browser.log.problems == []


MARGINS = """(function(){
  var strips=[...document.querySelectorAll('#sdi12-margins svg.sdi12-strip')];
  return strips.map(function(s){ var r=s.getBoundingClientRect();
    var limit=s.querySelector('.sdi12-limit'), ticks=s.querySelectorAll('.sdi12-tick');
    var fonts=[...s.querySelectorAll('text')].map(t=>parseFloat(getComputedStyle(t).fontSize));
    var tx=[...ticks].map(t=>t.getBoundingClientRect().x);
    return {id: s.dataset.requirement, width: r.width, height: r.height,
            limit: limit ? limit.getBoundingClientRect().x : null, ticks: tx,
            smallest_font: Math.min.apply(null, fonts), text: s.textContent}; });
})()"""


def test_the_margins_chart_shows_a_timing_fault_beyond_its_limit(reports, browser):
    """What a reader sees of a reply that starts late: R-7.0-10's ticks right of its limit
    line, the figures beside it, every strip readable at A4 width (794 px at 96 dpi)."""
    browser.open(reports["late"] / "report.html")
    strips = {s["id"]: s for s in browser.evaluate(MARGINS)}
    browser.screenshot(SCREENSHOTS / "report-margins-late.png",
                       "document.getElementById('sdi12-margins')")  # fmt: skip
    assert {"R-7.0-09", "R-7.0-10", "R-7.0-12"} <= set(strips)
    late = strips["R-7.0-10"]
    assert late["ticks"] and min(late["ticks"]) > late["limit"], late
    assert "FAIL" in late["text"] and "margin -4.60 ms" in late["text"]
    early = strips["R-7.0-09"]
    assert max(early["ticks"]) > early["limit"]  # 20 ms is well after the 7.93 ms minimum
    for s in strips.values():
        assert s["width"] <= 794 and s["height"] > 30, s
        assert s["smallest_font"] >= 9, s
    assert browser.log.problems == []


def test_a_long_reply_in_the_evidence_wraps_inside_the_page(reports, browser):
    """First-hour look (2026-12-05): abort-keeps-old-data quotes D0's reply
    '0-5.00-3.75-2.50-...' (80 characters without a space) as evidence; the Evidence column
    could not wrap it, the requirements table's narrowest width grew from 1129 to 1271
    pixels and a 1280-pixel window with its scrollbar scrolled sideways, the Tests column
    cut off. Squeezed, the column now keeps to its own width as in the clean run's report."""
    browser.open(reports["long"] / "report.html")
    widths = browser.evaluate(
        "(function(){ document.body.style.width = '600px';"
        " return [...document.querySelectorAll('#sdi12-requirements td:nth-child(6)')]"
        ".map(c => c.getBoundingClientRect().width); })()"
    )
    assert widths and max(widths) < 300, max(widths)  # 273 (260 + padding); 416 before
