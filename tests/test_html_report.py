"""The HTML report treats everything the DUT sent as untrusted text (design.md 7)."""

from __future__ import annotations

from types import SimpleNamespace

from conformance.reports import html
from conformance.results import CaseRecord
from conformance.run import ConformanceRun, RunOptions
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1
from conformance.verdicts import Finding, Verdict

HOSTILE = ["<script>alert(1)</script>", '"><img src=x onerror=alert(1)>']


def hostile_run() -> ConformanceRun:
    run = ConformanceRun(RunOptions())
    ident = SimpleNamespace(
        vendor=HOSTILE[0], model=HOSTILE[1], sensor_version="<b>", optional="</table>", version="14"
    )
    exchange = SimpleNamespace(answered=True, reply_text="014" + HOSTILE[0] + HOSTILE[1] + "\r\n")
    run.session = SimpleNamespace(
        identity=ident,
        ident_exchange=exchange,
        version="14",
        address="0",
        assumptions=[HOSTILE[1]],
        address_notes=[HOSTILE[0]],
        uncertainty=0.0,
    )
    run.finish(complete=True)
    return run


def test_header_escapes_the_identification():
    page = html.header(hostile_run())
    for bad in HOSTILE:
        assert bad not in page
    assert "&lt;script&gt;" in page
    assert "<img" not in page


def test_case_evidence_escapes_findings_and_wire_text():
    record = CaseRecord(
        "t::x", "x", ("R-4.4.2-01",), description=HOSTILE[0], expectation=HOSTILE[1]
    )
    record.findings.append(Finding("R-4.4.2-01", Verdict.FAIL, HOSTILE[1], evidence=[HOSTILE[0]]))
    wire = [
        Event(EventKind.CHAR, DUT, i * 0.00833, (i + 1) * 0.00833, wire=to_wire_7e1(ord(c)))
        for i, c in enumerate(HOSTILE[1])
    ]
    record.evidence.append(("reply", wire))
    page = html.case_html(record)
    for bad in HOSTILE:
        assert bad not in page
    assert "<img" not in page and "<script>alert" not in page


def test_requirements_table_and_banner_escape():
    run = hostile_run()
    page = html.banner(run) + html.requirements_table(run)
    assert "sdi12-verdict" in page and "sdi12-requirements" in page
    assert "<img" not in page
