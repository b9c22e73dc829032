"""Everything sdi12-conform adds to the pytest-html report.

A certifier opens the file and must see the overall verdict at once, then what to read first
(FAIL, ERROR, INCONCLUSIVE and WARN requirements with their reasons), the DUT and run identity,
and the full requirements table (sortable, filterable). Per case the report shows the
expectation, the findings, a timing diagram for timing cases and the wire transcript.

pytest-html puts its own title and environment table first and our hook output inside its
summary section; a few lines of script move our block right under the title so the verdict is
above the fold (without script the block still shows, just lower). Everything that came from
the DUT goes through :func:`html.escape` (design.md 7: the device is untrusted).
"""

from __future__ import annotations

from collections.abc import Sequence
from html import escape
from typing import TYPE_CHECKING, Any

import pytest

from ..catalog import requirement
from ..results import COMPLIANT, NON_COMPLIANT, CaseRecord, RequirementResult
from ..root_causes import reading_order
from ..run import TOOL_IDENTITY, ConformanceRun
from ..stash import CASE
from ..transcript import GOOD_PARITY, SEVEN_BITS, TOOL, Event, EventKind
from ..transcript import escape as wire_escape
from ..verdicts import Finding, Verdict
from .evidence import NEEDS_EVIDENCE, WireRef, locator_of
from .margins import margins_html
from .plan import plan_section, read_plan
from .sweep_chart import section as sweep_section
from .timing_diagram import exchange_behind, timing_svg, wire_title
from .verdicts_json import dut_block, duts_block

if TYPE_CHECKING:
    from .html_aside import Aside

# Severity order for the banner, the "read first" list and sorting the verdict column.
SEVERITY = ("ERROR", "FAIL", "INCONCLUSIVE", "WARN", "PASS", "N/A")
STYLE = """
<style>
#sdi12-top,#sdi12-top p,.sdi12,.sdi12-case{color:#222}
#results-table{color:#333}
.sdi12-banner{font:bold 30px sans-serif;padding:12px 20px;border-radius:6px;margin:10px 0;
  color:#fff}
.sdi12-banner.ok{background:#2e7d32}.sdi12-banner.bad{background:#c62828}
.sdi12-banner.incomplete{background:#ef6c00}
.sdi12-banner small{display:block;font:15px sans-serif;margin-top:4px}
.sdi12-banner .ident{font:13px monospace;opacity:.95}
.sdi12-cols{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}
.sdi12-cols h3{font:bold 14px sans-serif;margin:6px 0 2px}
table.sdi12{border-collapse:collapse;margin:6px 0;font:13px sans-serif}
table.sdi12 td,table.sdi12 th{border:1px solid #ccc;padding:3px 6px;vertical-align:top;
  text-align:left}
table.sdi12 th{background:#eee}
table.sdi12.kv th{font-weight:normal;color:#555;white-space:nowrap}
#sdi12-requirements thead th{cursor:pointer;user-select:none;position:sticky;top:0}
#sdi12-requirements thead th::after{content:" ⇅";color:#aaa}
#sdi12-requirements thead th.asc::after{content:" ▲";color:#333}
#sdi12-requirements thead th.desc::after{content:" ▼";color:#333}
#sdi12-requirements th{white-space:nowrap}
#sdi12-requirements td:nth-child(5){min-width:260px;max-width:420px}
#sdi12-requirements td:nth-child(6){min-width:260px;overflow-wrap:anywhere}
#sdi12-requirements td:nth-child(7){max-width:260px;font-size:12px}
.sdi12-legend{font:12px sans-serif;color:#555;margin:2px 0 6px}
.sdi12-attention .tests{color:#555;font-size:12px}
.sdi12-controls{font:13px sans-serif;margin:6px 0}
.sdi12-controls input,.sdi12-controls select{font:13px sans-serif;padding:2px 4px}
.v-PASS{color:#2e7d32;font-weight:bold}.v-FAIL{color:#c62828;font-weight:bold}
.v-WARN{color:#b26a00;font-weight:bold}.v-INCONCLUSIVE{color:#6a1b9a;font-weight:bold}
.v-NA{color:#666}.v-ERROR{color:#fff;background:#c62828;font-weight:bold}
.sdi12-attention li{margin:3px 0;font:13px sans-serif}
.sdi12-case{font:13px sans-serif}
.sdi12-case .num{font:12px monospace;white-space:nowrap}
.sdi12-wire{font:12px monospace;white-space:pre;background:#f7f7f7;border:1px solid #ddd;
  padding:4px 6px;overflow-x:auto}
.sdi12-wire .tool{color:#1565c0}.sdi12-wire .dut{color:#2e7d32}.sdi12-wire .brk{color:#b26a00}
.sdi12-wire .hdr{color:#777}.sdi12-wire .bad{color:#c62828;font-weight:bold}
.sdi12-wire .hit{background:#fff3c4;font-weight:bold}
.sdi12-where{border-left:4px solid #c62828;padding:2px 0 2px 10px;margin:8px 0}
.sdi12-where.WARN{border-color:#f9a825}.sdi12-where.INCONCLUSIVE{border-color:#8e24aa}
.sdi12-diagram{overflow-x:auto;margin:4px 0 8px;border:1px solid #eee;background:#fff}
.sdi12-wire,.sdi12-diagram{max-width:calc(100vw - 70px)}
#sdi12-top a,.sdi12-case a{color:#1565c0}
/* pytest-html's test-log leftovers: a certificate shows verdicts, not a test runner's tally */
#environment-header,#environment{display:none}
.filters input[disabled],.filters input[disabled]+span{display:none}
td.extra:has(.sdi12-case) .logwrapper{display:none}
tbody.sdi12-target{outline:3px solid #1565c0}
/* the Result cell draws the verdict; its text stays pytest's outcome for pytest-html's filters */
td.col-result.sdi12-verdict{font-size:0;white-space:nowrap}
td.col-result.sdi12-verdict::before{content:attr(data-verdict);font-size:13px}
td.col-result.sdi12-verdict::after{font-size:12px;font-weight:normal;color:#555}
td.sdi12-verdict.v-PASS{color:#2e7d32}td.sdi12-verdict.v-FAIL{color:#c62828}
td.sdi12-verdict.v-WARN{color:#b26a00}td.sdi12-verdict.v-INCONCLUSIVE{color:#6a1b9a}
td.sdi12-verdict.v-NA{color:#666}td.sdi12-verdict.v-ERROR{color:#fff}
.sdi12-rid,#sdi12-requirements td:first-child,table.sdi12 td:first-child{white-space:nowrap}
</style>
"""

SCRIPT = r"""
<script>
(function(){
  var top=document.getElementById('sdi12-top'), title=document.getElementById('title');
  if(top&&title){var after=title.nextElementSibling||title;
    after.parentNode.insertBefore(top,after.nextSibling);}
  var envh=document.getElementById('environment-header'),env=document.getElementById('environment');
  var results=document.getElementById('results-table');
  if(envh&&env&&results){results.parentNode.insertBefore(envh,results.nextSibling);
    envh.parentNode.insertBefore(env,envh.nextSibling);}
  if(top&&top.dataset.cases){
    var rc=document.querySelector('.run-count');
    if(rc) rc.textContent=rc.textContent.replace(/^\d+ tests? took/,
      top.dataset.cases+' conformance cases took');
    var credit=document.querySelector('a[href*="pypi/pytest-html"]'), p=credit&&credit.parentNode;
    var when=p&&p.textContent.match(/generated on (.+?) at (\S+)/);
    if(p&&when){var v=p.textContent.match(/v(\d\S*)\s*$/);
      p.textContent='Report by '+top.dataset.madeBy+', generated on '+when[1]+' at '+when[2]+
        ' (page layout: ';
      p.appendChild(credit); p.appendChild(document.createTextNode((v?' v'+v[1]:'')+')'));}}
  var h=document.querySelector('.summary__data h2');
  if(h) h.textContent='Evidence: the conformance cases';
  function findCase(name){var hit=null;
    document.querySelectorAll('#results-table tbody.results-table-row').forEach(function(b){
      if(b.id&&(b.id===name||b.id.slice(-name.length-2)==='::'+name)) hit=b;});
    return hit;}
  function openCase(name){var b=findCase(name); if(!b) return;
    var closed=b.querySelector('.collapsible > .col-result.collapsed');
    if(closed){closed.click(); b=findCase(name);}
    if(!b) return;
    document.querySelectorAll('tbody.sdi12-target').forEach(function(o){
      o.classList.remove('sdi12-target');});
    b.classList.add('sdi12-target'); b.scrollIntoView(); window.scrollBy(0,-8);}
  document.addEventListener('click',function(e){
    var a=e.target.closest&&e.target.closest('a[data-sdi12-case]'); if(!a) return;
    e.preventDefault(); openCase(a.dataset.sdi12Case);});
  var t=document.getElementById('sdi12-requirements'); if(!t) return;
  var f=document.getElementById('sdi12-filter'), v=document.getElementById('sdi12-verdict-filter');
  var shown=document.getElementById('sdi12-shown');
  function apply(){var q=f.value.toLowerCase(), want=v.value, n=0;
    t.querySelectorAll('tbody tr').forEach(function(r){
      var ok=r.textContent.toLowerCase().indexOf(q)>=0&&(!want||r.dataset.verdict===want);
      r.style.display=ok?'':'none'; if(ok) n++;});
    shown.textContent=n+' of '+t.tBodies[0].rows.length+' requirements shown';}
  f.addEventListener('input',apply); v.addEventListener('change',apply);
  document.querySelectorAll('[data-sdi12-show]').forEach(function(a){
    a.addEventListener('click',function(e){e.preventDefault();v.value=a.dataset.sdi12Show;
      f.value='';apply();t.scrollIntoView();});});
  t.querySelectorAll('thead th').forEach(function(th,i){th.addEventListener('click',function(){
    var rows=Array.prototype.slice.call(t.tBodies[0].rows);
    var asc=!th.classList.contains('asc');
    t.querySelectorAll('thead th').forEach(function(h){h.classList.remove('asc','desc');});
    th.classList.add(asc?'asc':'desc');
    function key(r){var c=r.cells[i];return c.dataset.sort||c.textContent;}
    rows.sort(function(a,b){var o=key(a).localeCompare(key(b),undefined,{numeric:true});
      return asc?o:-o;});
    rows.forEach(function(r){t.tBodies[0].appendChild(r);});});});
  apply();
})();
</script>
"""


def verdict_class(verdict: str) -> str:
    return "v-NA" if verdict in ("N/A", "NOT SELECTED") else f"v-{verdict}"


def _verdict_cell(verdict: str) -> str:
    rank = SEVERITY.index(verdict) if verdict in SEVERITY else len(SEVERITY)
    return f'<td class="{verdict_class(verdict)}" data-sort="{rank}">{escape(verdict)}</td>'


def _tally(results: list[RequirementResult]) -> dict[str, int]:
    tally = dict.fromkeys(SEVERITY, 0)
    for r in results:
        if r.selected:  # a partial run counts what it selected
            tally[str(r.verdict)] = tally.get(str(r.verdict), 0) + 1
    return tally


def banner(run: ConformanceRun) -> str:
    """The overall verdict, the requirement counts and who was judged, in one block."""
    verdict = run.verdict or "INCOMPLETE"
    css = {COMPLIANT: "ok", NON_COMPLIANT: "bad"}.get(verdict, "incomplete")
    results = run.results or []
    tally = _tally(results)
    counts = ", ".join(f"{n} {k}" for k, n in tally.items() if n)
    testable = sum(1 for r in results if r.requirement.testable(run.options.role))
    line = f"{counts} — {len(results)} requirements, {testable} testable by this tool"
    left_out = sum(1 for r in results if not r.selected)
    if run.selection.partial:
        verdict = f"{verdict} · partial run"
        line += (
            f" — partial run ({run.selection.describe()}): {left_out} requirements not "
            "selected; the verdict covers the selected ones only"
        )
    if run.stop_reason:
        line += f" — {'note' if run.complete else 'stopped'}: {run.stop_reason}"
    who = f"{_who(run)} · port {run.options.port} · {run.finished or run.started}"
    return (
        f'<div class="sdi12-banner {css}" id="sdi12-verdict">{escape(verdict)}'
        f"<small>{escape(line)}</small>"
        f'<small class="ident">{escape(who)}</small></div>'
    )


def _who(run: ConformanceRun) -> str:
    """The DUT in one line: a sensor by address and its aI! reply; a recorder by its claim."""
    dut = dut_block(run)
    version = dut["sdi12_version"] or "?"
    if run.options.role == "recorder":
        return f"data recorder, SDI-12 v{version}"
    ident = wire_escape(dut["identification"] or "(no identification)")
    return f"sensor at address {dut['address']}, SDI-12 v{version}: {ident}"


def _kv_table(title: str, rows: list[tuple[str, object]], table_id: str) -> str:
    body = "".join(f"<tr><th>{escape(k)}</th><td>{escape(str(v))}</td></tr>" for k, v in rows)
    table = f'<table class="sdi12 kv" id="{table_id}">{body}</table>'
    return f"<div><h3>{escape(title)}</h3>{table}</div>"


def _counted(notes: list[str]) -> str:
    """Repeated notes once each, with their count (three restores read as one line)."""
    seen: dict[str, int] = {}
    for note in notes:
        seen[note] = seen.get(note, 0) + 1
    return "; ".join(n if k == 1 else f"{n} (×{k})" for n, k in seen.items())


def bench_rows(bench: dict[str, Any] | None) -> list[tuple[str, str]]:
    """What the report says about a real bench: echo, breaks, direction, measured timing."""
    if not bench:
        return []
    echo = "yes" if bench["echo"] else "no"
    if bench["echo_collisions"] or bench["echo_missing"]:
        echo += (
            f" ({bench['echo_collisions']} echoes differed from what was sent: collisions; "
            f"{bench['echo_missing']} not heard back)"
        )
    timing = bench["timing"]
    return [
        ("Interface echoes the tool", f"{echo} (--echo {bench['echo_mode']})"),
        ("Breaks and pulses made", str(bench["breaks"])),
        ("Transmit enable", str(bench["direction"])),
        ("Timing measured", str(timing["summary"])),
    ]


def _talk_rows(link: dict[str, Any]) -> list[tuple[str, str]]:
    """Listen before talk (sensor role): how often the tool waited for the DUT to finish,
    and the collisions that happened anyway (never evidence against the DUT)."""
    if "collisions" not in link:
        return []
    return [
        (
            "Listen before talk",
            f"{link['talk_holds']} transmissions held until the DUT was quiet; "
            f"{link['collisions']} collisions (noted in the transcript)",
        )
    ]


def _other_sensors(duts: list[dict[str, Any]]) -> str:
    """The other sensors a recording shows, one phrase each: address and identification
    (escaped by the table that shows it, as every DUT field)."""
    ident = {d["address"]: d["identification"] for d in duts}
    return "; ".join(
        f"{a}: {wire_escape(i.strip()) if i else '(no aI! reply seen)'}" for a, i in ident.items()
    )


def header(run: ConformanceRun) -> str:
    """The DUT identity and the run's identity, side by side."""
    dut = dut_block(run)
    link = run.link_description()
    uncertainty = link["timing_uncertainty_ms"]
    exact = " (virtual clock: exact)" if link["kind"] == "sim" and not uncertainty else ""
    breaks = {True: "yes", False: "no", None: "unknown"}[link["can_break"]]
    sensor = [
        ("Identification (aI!)", wire_escape(dut["identification"] or "(none)")),
        ("Address", dut["address"] or "—"),
        ("Claimed SDI-12 version", dut["sdi12_version"] or "unknown"),
        ("Vendor", dut["vendor"] or "—"),
        ("Model", dut["model"] or "—"),
        ("Firmware (sensor version)", dut["firmware"] or "—"),
        ("Serial / optional field", dut["serial"] or "—"),
    ]
    recorder = [
        ("Kind", "data recorder (the tool plays the sensors)"),
        ("Claimed SDI-12 version", dut["sdi12_version"] or "unknown"),
    ]
    device = [
        *(recorder if run.options.role == "recorder" else sensor),
        ("Declaration", dut["declaration"] or "none (features discovered)"),
        ("Assumptions", "; ".join(dut["assumptions"]) or "none"),
    ]
    if run.options.role == "sensor":  # the tool only changes a sensor's address
        device.append(("Address changes", _counted(dut.get("address_notes") or []) or "none made"))
    others = [d for d in duts_block(run) or [] if d["address"] != dut["address"]]
    if others:  # a bus of sensors judged passively: each has its own report
        device.append(("Other sensors on the bus", _other_sensors(others)))
    runrows = [
        ("Tool", f"{TOOL_IDENTITY['name']} {TOOL_IDENTITY['version']}"),
        ("Role judged", run.options.role),
        ("Port", run.options.port),
        ("Link", f"{link['kind']}, can send breaks: {breaks}"),
        ("Timing uncertainty", f"±{uncertainty} ms{exact}"),
        *bench_rows(link.get("bench")),
        *_talk_rows(link),
        *(
            [("Harness stderr (its last 2000 characters)", link["harness_stderr"] or "none")]
            if "harness_stderr" in link
            else []
        ),
        ("Started", run.started),
        ("Finished", run.finished or "—"),
        ("Strict (SHOULD as MUST)", "yes" if run.options.strict else "no"),
        ("Ran to the end", _ran_to_the_end(run)),
    ]
    if run.stop_reason:
        runrows.append(("Note" if run.complete else "Stopped because", run.stop_reason))
    return (
        '<div class="sdi12-cols" id="sdi12-header">'
        + _kv_table("Device under test", device, "sdi12-dut")
        + _kv_table("Run", runrows, "sdi12-run")
        + "</div>"
    )


def _ran_to_the_end(run: ConformanceRun) -> str:
    """A run stopped for a stated reason (no device answered) was neither interrupted nor
    failed by its link: the row points at the reason rather than guess one."""
    if run.complete:
        return "yes"
    if run.stop_reason:
        return "no (see Stopped because)"
    return "no (interrupted or the link failed)"


def attention(run: ConformanceRun) -> str:
    """What a certifier must read first: every requirement that is not a plain PASS or N/A."""
    results = run.results or []
    bad = [r for r in results if str(r.verdict) in SEVERITY[:4]]
    bad.sort(key=lambda r: SEVERITY.index(str(r.verdict)))
    bad = reading_order(bad)  # root causes first, each followed by what it drags
    na = sum(1 for r in results if r.verdict is Verdict.NA and r.selected)
    na_link = (
        f"<p>{na} requirements are N/A (not applicable to this DUT, or not testable by this tool):"
        ' <a href="#sdi12-requirements" data-sdi12-show="N/A">show them with their reasons</a>.</p>'
        if na
        else ""
    )
    if not bad:
        return (
            '<div id="sdi12-attention"><h3>Read first</h3><p>Nothing: no requirement failed, '
            f"warned or was left inconclusive.</p>{na_link}</div>"
        )
    items = [_attention_item(group) for group in _same_reason(bad)]
    return (
        f'<div id="sdi12-attention"><h3>Read first ({len(bad)})</h3>'
        f'<ul class="sdi12-attention">{"".join(items)}</ul>{na_link}</div>'
    )


def _reason(r: RequirementResult) -> str:
    reasons = [f.detail for f in r.findings if f.verdict is r.verdict]
    more = f" (+{len(reasons) - 1} more)" if len(reasons) > 1 else ""
    return (reasons[0] if reasons else "") + more


def _same_reason(results: list[RequirementResult]) -> list[list[RequirementResult]]:
    """Requirements with one verdict and one reason, together: a `-k` run leaves dozens
    "not judged", which read better as one line than as a page."""
    groups: dict[tuple[str, str], list[RequirementResult]] = {}
    for r in results:
        groups.setdefault((str(r.verdict), _reason(r)), []).append(r)
    return list(groups.values())


def _attention_item(group: list[RequirementResult]) -> str:
    verdict = str(group[0].verdict)
    if len(group) == 1:
        ids = f"<b>{escape(group[0].requirement.id)}</b> ({escape(group[0].requirement.level)})"
    else:
        listed = ", ".join(r.requirement.id for r in group)
        ids = f"{len(group)} requirements: <b>{escape(listed)}</b>"
    tests = sorted({t.split("::")[-1] for r in group for t in r.tests})
    links = ", ".join(case_link(t) for t in tests)
    where = f' <span class="tests">[evidence: {links}]</span>' if tests else ""
    return (
        f'<li><span class="{verdict_class(verdict)}">{escape(verdict)}</span> {ids}: '
        f"{escape(_reason(group[0]))}{where}</li>"
    )


def case_link(name: str) -> str:
    """A link that opens the case's row in the evidence table below and scrolls to it."""
    return f'<a href="#" data-sdi12-case="{escape(name)}">{escape(name)}</a>'


def requirements_table(run: ConformanceRun) -> str:
    rows = []
    for r in run.results or []:
        req = r.requirement
        verdict = str(r.verdict) if r.selected else "NOT SELECTED"
        tests = "<br>".join(case_link(t.split("::")[-1]) for t in r.tests) or "—"
        extra = len(r.findings) - 1
        evidence = escape(r.one_line) + (f" <i>(+{extra} findings)</i>" if extra > 0 else "")
        rows.append(
            f'<tr data-verdict="{escape(verdict)}"><td>{escape(req.id)}</td>'
            f"<td>{escape(req.clause)}</td><td>{escape(req.level)}</td>{_verdict_cell(verdict)}"
            f"<td>{escape(req.statement)}</td><td>{evidence}</td><td>{tests}</td></tr>"
        )
    shown = SEVERITY + (("NOT SELECTED",) if run.selection.partial else ())
    options = "".join(f'<option value="{escape(v)}">{escape(v)}</option>' for v in shown)
    return (
        "<h2>Requirements</h2>"
        '<div class="sdi12-controls">Filter: <input id="sdi12-filter" '
        'placeholder="ID, clause, text..." size="28"> Verdict: <select id="sdi12-verdict-filter">'
        f'<option value="">all</option>{options}</select> <span id="sdi12-shown"></span> '
        "· click a column heading to sort</div>"
        '<p class="sdi12-legend">PASS: met · FAIL: a MUST broken · WARN: a SHOULD broken or an '
        "ambiguity decided leniently · INCONCLUSIVE: could not be decided (see why) · N/A: not "
        "applicable to this DUT, or not testable by this tool · ERROR: the tool failed</p>"
        '<table class="sdi12" id="sdi12-requirements"><thead><tr><th>ID</th><th>Clause</th>'
        "<th>Level</th><th>Verdict</th><th>Requirement</th><th>Evidence</th><th>Tests</th>"
        f"</tr></thead><tbody>{''.join(rows)}</tbody></table>"
    )


def transcript_html(label: str, events: list[Event], marked: frozenset[Event] = frozenset()) -> str:
    """The wire log: one line per break, note or run of characters from one side; lines
    holding a ``marked`` event (the exchange a finding rests on) are highlighted with ▶."""
    if not events:
        return f"<p><b>Wire: {escape(label)}</b>: no bus events</p>"
    t0 = events[0].start
    lines = [
        f'<span class="hdr">t (ms)     marking  dir          characters   '
        f"(t = 0 is {t0:.4f} s on the link clock)</span>"
    ]
    previous_end: float | None = None
    for group in _group(events):
        first = group[0]
        at = f"{(first.start - t0) * 1e3:9.2f}"
        idle = "" if previous_end is None else f"{(first.start - previous_end) * 1e3:.2f}"
        prefix = f"{at} {idle:>10}  "
        if marked:
            hit = any(e in marked for e in group)
            prefix = ("▶ " if hit else "  ") + prefix
            if hit:
                lines.append(None)  # placeholder: the next line gets the highlight
        if first.kind is EventKind.BREAK:
            lines.append(f'<span class="brk">{prefix}BREAK {first.duration * 1e3:.2f} ms</span>')
        elif first.kind is EventKind.NOTE:
            lines.append(f"{prefix}note  {escape(first.text)}")
        else:
            who = "tool" if first.origin == TOOL else "dut"
            arrow = "→ sensor  " if who == "tool" else "← sensor  "
            text, bad = _line_chars(group)
            parity = f'  <span class="bad">[{bad} parity error(s)]</span>' if bad else ""
            lines.append(
                f'<span class="{who}">{prefix}{arrow}{escape(text)}'
                f"  ({len(group)} chars, ends {(group[-1].end - t0) * 1e3:.2f})</span>{parity}"
            )
        if first.kind is not EventKind.NOTE:
            previous_end = group[-1].end
    wire = "\n".join(_highlighted(lines))
    return f'<p><b>Wire: {escape(label)}</b></p><div class="sdi12-wire">{wire}</div>'


def _line_chars(group: list[Event]) -> tuple[str, int]:
    """A line's characters (escaped, parity bit dropped) and how many of them fail
    ``Event.parity_ok``."""
    wires = bytes([e.wire for e in group])
    return wire_escape(wires.translate(SEVEN_BITS)), len(wires.translate(None, GOOD_PARITY))


def _highlighted(lines: list[str | None]) -> list[str]:
    """The lines with each one after a ``None`` placeholder wrapped as a hit."""
    out: list[str] = []
    hit = False
    for line in lines:
        if line is None:
            hit = True
            continue
        out.append(f'<span class="hit">{line}</span>' if hit else line)
        hit = False
    return out


CONTEXT_LINES = 2  # wire lines shown before and after the exchange a finding rests on
CASE_EXCERPT = 24  # events of a case's whole traffic shown (the rest: transcript.jsonl)


def where_html(findings: list[Finding], ref: WireRef, events: Sequence[Event], timing: bool) -> str:
    """The wire lines around the exchange ``findings`` rest on, with times, that exchange
    highlighted (and drawn, for a timing case): the FAIL is shown where it happened."""
    lo = max(0, ref.first - 60)
    return where_html_around(findings, ref, list(events[lo : around_end(ref)]), lo, timing)


def around_end(ref: WireRef) -> int:
    """Where the events :func:`where_html_around` reads for ``ref`` end: 60 past its
    exchange, or for a case's own traffic (no exchange) the first :data:`CASE_EXCERPT` of
    it, all it shows: a judged recording's case may span the whole recording (issue 22:
    reading it all for the excerpt made 10^5 events at 30 minutes of a measuring bus)."""
    if ref.exchange is None:
        return min(ref.last + 61, ref.first + CASE_EXCERPT)
    return ref.last + 61


def where_html_around(
    findings: list[Finding], ref: WireRef, around: list[Event], lo: int, timing: bool
) -> str:
    """:func:`where_html` from the events it shows alone: ``around``, the transcript's
    events ``lo..ref.last+60`` (up to 60 before the exchange, as many after), which a
    recording read again as it comes gives without a list of every event (issue 22); for a
    case's own traffic, up to :func:`around_end` (its first :data:`CASE_EXCERPT` events)."""
    worst = max((f.verdict for f in findings), key=lambda v: v.rank)
    rids = ", ".join(dict.fromkeys(f.requirement for f in findings))
    first, last = ref.first - lo, ref.last + 1 - lo
    span = around[first:last]
    if ref.exchange is None:
        what = "the case's own traffic (no single exchange named or measured)"
        shown = span[:CASE_EXCERPT]
        more = ref.last + 1 - ref.first - len(shown)  # the span's events past those shown
        tail = f"; {more} more events in transcript.jsonl" if more > 0 else ""
        marked: frozenset[Event] = frozenset()
    else:
        what = f"the exchange {wire_escape(ref.exchange)} (found by {ref.how})"
        before = _group(around[:first])[-CONTEXT_LINES:]
        after = _group(around[last:])[:CONTEXT_LINES]
        shown = [e for g in before for e in g] + span + [e for g in after for e in g]
        tail = ""
        marked = frozenset(span)
    head = (
        f"<p><b>Where: {escape(rids)} {escape(str(worst))}</b> rests on {escape(what)}: "
        f"transcript.jsonl events {ref.first}–{ref.last}, t = {ref.start_s:.4f}–"
        f"{ref.end_s:.4f} s on the link clock{escape(tail)}</p>"
    )
    parts = [head]
    if timing and ref.exchange is not None:
        svg = timing_svg(span, title=ref.exchange)
        if svg:
            parts.append(f'<div class="sdi12-diagram">{svg}</div>')
    parts.append(transcript_html(f"around {ref.exchange or 'the case'}", shown, marked))
    return f'<div class="sdi12-where {escape(str(worst))}">{"".join(parts)}</div>'


def _group(events: list[Event]) -> list[list[Event]]:
    """Runs of characters from one side with gaps under two frame times form one line."""
    groups: list[list[Event]] = []
    char = EventKind.CHAR
    # the previous event's fields (groups[-1][-1]'s), read once per event
    group: list[Event] = []
    last_kind: EventKind | None = None
    last_origin = ""
    last_end = 0.0
    for e in events:
        kind, origin = e.kind, e.origin
        if (
            kind is char
            and last_kind is char
            and origin == last_origin
            and (e.start - last_end < 0.0167)
        ):
            group.append(e)
        else:
            group = [e]
            groups.append(group)
        last_kind, last_origin, last_end = kind, origin, e.end
    return groups


def is_timing_case(record: CaseRecord) -> bool:
    """A case that judges a requirement the catalog checks by timing (its Check column), or
    that measured a time: its evidence is drawn as a timing diagram. Where the case is
    written (its module's name) does not matter."""
    return any(f.measured_ms is not None for f in record.findings) or any(
        "timing" in requirement(rid).check for rid in record.requirements
    )


def _observation(f: Finding) -> str:
    text = escape(f.detail)
    if f.measured_ms is not None:
        u = f" ± {f.uncertainty_ms:.2f}" if f.uncertainty_ms is not None else ""
        limit = f", limit {f.limit_ms:.2f} ms" if f.limit_ms is not None else ""
        text += f'<br><span class="num">measured {f.measured_ms:.2f}{u} ms{limit}</span>'
    if f.evidence:
        text += f"<br><i>{escape('; '.join(f.evidence))}</i>"
    if f.decision:
        text += f" <i>(decision {escape(f.decision)})</i>"
    return text


def case_html(
    record: CaseRecord,
    derived: tuple[str, list[Event]] | None = None,
    where: str = "",
) -> str:
    """One case: what it checks, what a conforming DUT does, what happened, and the wire.

    ``derived`` is evidence the report found for a case that attached none (a whole-run
    timing case): the exchange behind its worst measurement, cut from the run's transcript.
    ``where`` (:func:`where_html`) shows the exchange each FAIL, WARN or INCONCLUSIVE rests
    on, right under the findings and before any other evidence.
    """
    parts = []
    if record.description:
        parts.append(f"<p><b>Case</b>: {escape(record.description)}</p>")
    if record.expectation:
        parts.append(f"<p><b>Expectation</b>: {escape(record.expectation)}</p>")
    rows = "".join(
        f"<tr><td>{escape(f.requirement)}</td>{_verdict_cell(str(f.verdict))}"
        f"<td>{_observation(f)}</td></tr>"
        for f in record.findings
    )
    parts.append(
        '<p><b>Observation</b></p><table class="sdi12"><tr><th>Requirement</th><th>Verdict</th>'
        f"<th>Finding</th></tr>{rows}</table>"
    )
    parts.append(where)
    evidence = list(record.evidence) or ([derived] if derived and not where else [])
    timing = is_timing_case(record)
    for label, events in evidence:
        if timing:
            svg = timing_svg(events, title=label)
            if svg:
                parts.append(
                    f"<p><b>Timing: {escape(wire_title(label, events))}</b></p>"
                    f'<div class="sdi12-diagram">{svg}</div>'
                )
        parts.append(transcript_html(label, events))
    return f'<div class="sdi12-case">{"".join(parts)}</div>'


class HtmlReportPlugin:
    """pytest-html hooks, bound to the run whose verdicts they show.

    ``defer_cases``: each case's HTML piece is made when the page is rendered rather than
    as the case ends (the same text: it reads the case's record and the events up to its
    end), so a page rendered by another process (:mod:`.html_aside`) takes that work off
    the run; the pieces wait in pytest-html's extras, which it keeps by reference."""

    def __init__(self, run: ConformanceRun, *, defer_cases: bool = False) -> None:
        self.run = run
        self.defer_cases = defer_cases
        self._pending: list[tuple[CaseRecord, dict[str, Any]]] = []
        #: set in the parent while another process renders the page (html_aside)
        self.aside: Aside | None = None

    def fill_cases(self) -> None:
        """The deferred cases' HTML pieces, into the extras pytest-html holds."""
        for record, extra in self._pending:
            extra["content"] = case_html(record, self._derived(record), self._where(record))
        self._pending.clear()

    def pytest_html_report_title(self, report: Any) -> None:
        report.title = f"SDI-12 conformance report ({self.run.options.role})"

    def pytest_html_results_summary(
        self, prefix: list[str], summary: list[str], postfix: list[str], session: Any
    ) -> None:
        if self.aside is not None:  # another process renders the page (html_aside)
            self.aside.summary_lists = (prefix, summary, postfix)
            return
        self.fill_cases()
        if self.run.results is None:
            return
        top = banner(self.run) + header(self.run) + attention(self.run)
        top += margins_html(self.run.results)
        judged = {c.nodeid: {"verdict": str(c.verdict), "bus_s": c.bus_s} for c in self.run.cases}
        top += plan_section(read_plan(self.run.report_dir()), judged)
        top += sweep_section(self.run)  # --sweep only
        made_by = escape(f"{TOOL_IDENTITY['name']} {TOOL_IDENTITY['version']}")
        prefix.extend(
            [
                STYLE,
                f'<div id="sdi12-top" data-cases="{len(self.run.cases)}" '
                f'data-made-by="{made_by}">{top}{requirements_table(self.run)}</div>',
            ]
        )
        postfix.append(SCRIPT)

    def pytest_html_results_table_header(self, cells: list[str]) -> None:
        cells[0] = cells[0].replace(">Result<", ">Verdict<")
        cells.insert(1, "<th>Requirements</th>")

    def pytest_html_results_table_row(self, report: Any, cells: list[str]) -> None:
        """pytest-html's Result cell shows the case's verdict, not pytest's outcome ("Skipped"
        for INCONCLUSIVE and N/A, issue 19). The outcome stays the cell's text, which
        pytest-html's filters and sorting read; the stylesheet draws ``data-verdict``."""
        verdict = getattr(report, "sdi12_verdict", "")
        if verdict:
            cells[0] = cells[0].replace(
                '<td class="col-result">',
                f'<td class="col-result sdi12-verdict {verdict_class(verdict)}" '
                f'data-verdict="{escape(verdict)}">',
                1,
            )
        reqs = "".join(
            f'<span class="sdi12-rid">{escape(r)}</span> '
            for r in getattr(report, "sdi12_requirements", ())
        )
        cells.insert(1, f"<td>{reqs.rstrip()}</td>")

    def _where(self, record: CaseRecord) -> str:
        """Per exchange, the FAIL/WARN/INCONCLUSIVE findings of the case resting on it."""
        if self.run.link is None:
            return ""
        locator = locator_of(self.run.link)
        grouped: dict[WireRef, list[Finding]] = {}
        for f in record.findings:
            if f.verdict in NEEDS_EVIDENCE:
                ref = locator.locate(f, record)
                if ref is not None:
                    grouped.setdefault(ref, []).append(f)
        timing = is_timing_case(record)
        return "".join(
            where_html_around(fs, ref, locator.slice(lo, around_end(ref)), lo, timing)
            for ref, fs in grouped.items()
            for lo in (max(0, ref.first - 60),)
        )

    def _derived(self, record: CaseRecord) -> tuple[str, list[Event]] | None:
        """For a timing case without evidence, the run's exchange behind its worst finding."""
        if record.evidence or not is_timing_case(record) or self.run.link is None:
            return None
        return exchange_behind(record.findings, self.run.link.transcript)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_makereport(self, item: Any, call: Any):
        report = yield
        record = item.stash.get(CASE, None)
        if record is not None and report.when == "call":
            from pytest_html import extras

            if self.defer_cases:  # made with the page (fill_cases)
                extra = extras.html("")
                self._pending.append((record, extra))
            else:
                extra = extras.html(case_html(record, self._derived(record), self._where(record)))
            report.extras = [*getattr(report, "extras", []), extra]
        return report
