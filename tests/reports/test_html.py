"""The HTML report treats everything the DUT sent as untrusted text (design.md 7)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from types import SimpleNamespace

from conformance.dut import DutClaim, Session
from conformance.reports import html, timing_diagram
from conformance.results import CaseRecord
from conformance.run import ConformanceRun, RunOptions
from conformance.transcript import DUT, TOOL, Event, EventKind, decode_7e1, to_wire_7e1
from conformance.transcript import escape as wire_escape
from conformance.verdicts import Finding, Verdict

HOSTILE = ["<script>alert(1)</script>", '"><img src=x onerror=alert(1)>']


class HostileSession(Session):
    """A session whose DUT says hostile things about itself."""

    def __init__(self, said: DutClaim) -> None:
        self.said = said
        self.version = "14"
        self.address = "0"
        self.assumptions = [HOSTILE[1]]
        self.address_notes = [HOSTILE[0]]
        self.uncertainty = 0.0

    def claim(self) -> DutClaim:
        return self.said


def hostile_run() -> ConformanceRun:
    run = ConformanceRun(RunOptions())
    ident = SimpleNamespace(
        vendor=HOSTILE[0], model=HOSTILE[1], sensor_version="<b>", optional="</table>", version="14"
    )
    exchange = SimpleNamespace(answered=True, reply_text="014" + HOSTILE[0] + HOSTILE[1] + "\r\n")
    run.session = HostileSession(DutClaim(ident, exchange.reply_text, "14"))  # type: ignore[arg-type]
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
    record.findings.append(
        Finding("R-4.4.2-01", Verdict.FAIL, HOSTILE[1], evidence=[HOSTILE[0]], observed=1)
    )
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


# -- timing diagrams -----------------------------------------------------------------------
CHAR = 10 / 1200  # one frame, s
SVG_TAGS = {"svg", "g", "rect", "text", "title", "line", "path"}


def chars(
    origin: str, text: str, start: float, gaps: dict[int, float] | None = None
) -> list[Event]:
    """Back-to-back 7E1 characters from ``start``; ``gaps`` adds marking before index i."""
    out, t = [], start
    for i, c in enumerate(text):
        t += (gaps or {}).get(i, 0.0)
        out.append(Event(EventKind.CHAR, origin, t, t + CHAR, wire=to_wire_7e1(ord(c))))
        t += CHAR
    return out


def exchange(start: float, command: str, reply: str, delay: float, **kw) -> list[Event]:
    brk = Event(EventKind.BREAK, TOOL, start, start + 0.013)
    cmd = chars(TOOL, command, brk.end + 0.009)
    return [brk, *cmd, *chars(DUT, reply, cmd[-1].end + delay, **kw)]


def parse_svg(svg: str) -> ET.Element:
    root = ET.fromstring(svg)  # well-formed, so no DUT text escaped into markup
    tags = {el.tag.split("}")[-1] for el in root.iter()}
    assert tags <= SVG_TAGS, tags
    return root


def red_labels(root: ET.Element) -> set[str]:
    bad = timing_diagram.COLOURS["bad"]
    return {
        el.text or "" for el in root.iter() if el.tag.endswith("text") and el.get("fill") == bad
    }


def texts(root: ET.Element) -> list[str]:
    return [el.text or "" for el in root.iter() if el.tag.endswith("text")]


def test_timing_svg_draws_break_marking_characters_window_and_gap():
    events = exchange(0.0, "0!", "0\r\n", 0.009) + exchange(
        2.0, "0D0!", "0+<1\r\n", 0.009, gaps={2: 0.003}
    )
    root = parse_svg(timing_diagram.timing_svg(events, title="two exchanges"))
    labels = texts(root)
    assert "break 13.00 ms" in labels and "marking 9.00 ms" in labels
    assert labels.count("reply +9.00 ms") == 2
    assert "gap 3.00 ms" in labels
    assert "<" in labels and "CR" in labels and "LF" in labels  # glyphs, escaped in the source
    assert "idle" in labels and any(t.endswith(" s") and t.startswith("1.") for t in labels)
    windows = [r for r in root.iter() if r.get("fill-opacity") == "0.22"]
    assert len(windows) == 2, "one reply window per command"
    two_seconds = 2e3 * timing_diagram.PX_PER_MS
    assert float(root.get("width")) < two_seconds / 3, "two seconds of idle are cut out"
    assert {"87 ms", "100 ms"} <= set(labels), "the windows after a reply are drawn"
    assert all(float(t.get("font-size")) >= 11 for t in root.iter() if t.tag.endswith("text"))


def test_timing_svg_marks_a_late_reply_and_an_overlong_gap_as_out_of_limits():
    root = parse_svg(
        timing_diagram.timing_svg(exchange(0.0, "0!", "0\r\n", 0.020, gaps={1: 0.003}))
    )
    assert {"reply +20.00 ms", "gap 3.00 ms"} <= red_labels(root)
    ok = parse_svg(timing_diagram.timing_svg(exchange(0.0, "0!", "0\r\n", 0.009)))
    assert red_labels(ok) == set()


def test_timing_svg_of_hostile_characters_is_inert():
    root = parse_svg(timing_diagram.timing_svg(exchange(0.0, "0!", HOSTILE[1], 0.009), HOSTILE[0]))
    assert root.get("aria-label").startswith(HOSTILE[0] + " (drawn as on the wire: break")
    glyphs = "".join(t for t in texts(root) if len(t) == 1)
    assert glyphs == "0!" + HOSTILE[1].replace(" ", "␣")
    assert timing_diagram.timing_svg([]) == ""


def test_exchange_behind_a_whole_run_finding_is_the_one_measured():
    events = exchange(0.0, "0!", "0\r\n", 0.009) + exchange(1.0, "0I!", "014X\r\n", 0.0153)
    finding = Finding(
        "R-7.0-10", Verdict.PASS, "worst", measured_ms=15.3, limit_ms=15.4, observed=1
    )
    label, drawn = timing_diagram.exchange_behind([finding], events)
    assert label.startswith("0I!, the exchange behind R-7.0-10's 15.30 ms")
    assert decode_7e1(e for e in drawn if e.origin == DUT) == "014X\r\n"
    assert drawn[0].kind is EventKind.BREAK
    assert (
        timing_diagram.exchange_behind([Finding("R-7.0-10", Verdict.PASS, "x", observed=1)], events)
        is None
    )


def test_case_html_draws_timing_cases_only():
    events = exchange(0.0, "0!", "0\r\n", 0.009)
    timing = CaseRecord("test_7_timing.py::test_x", "test_x", ("R-7.0-05",))
    timing.findings.append(Finding("R-7.0-05", Verdict.PASS, "answered", observed=1))
    timing.evidence.append(("break, a!", events))
    other = CaseRecord("test_4_4_basic.py::test_y", "test_y", ("R-4.4.1-01",))
    other.findings.append(Finding("R-4.4.1-01", Verdict.PASS, "answered", observed=1))
    other.evidence.append(("a!", events))
    assert "<svg" in html.case_html(timing) and "<svg" not in html.case_html(other)
    # the catalog decides, not the module's name: a protocol rule in a timing module draws none
    named = CaseRecord("test_7_timing.py::test_w", "test_w", ("R-4.4.1-01",))
    named.evidence.append(("a!", events))
    assert "<svg" not in html.case_html(named)
    elsewhere = CaseRecord("test_4_4_basic.py::test_v", "test_v", ("R-7.0-05",))
    elsewhere.evidence.append(("break, a!", events))
    assert "<svg" in html.case_html(elsewhere)
    derived = ("worst exchange", events)
    measured = CaseRecord("test_9_whole_run.py::test_z", "test_z", ("R-7.0-10",))
    measured.findings.append(Finding("R-7.0-10", Verdict.PASS, "ok", measured_ms=9.0, observed=1))
    page = html.case_html(measured, derived)
    assert "<svg" in page and "worst exchange" in page and "measured 9.00 ms" in page


def test_read_first_groups_requirements_with_one_reason_and_header_says_why_incomplete():
    run = ConformanceRun(RunOptions())
    run.finish(complete=True)  # no case ran: every testable requirement is left unjudged
    unjudged = [r for r in run.results if r.verdict is Verdict.INCONCLUSIVE]
    page = html.attention(run)
    assert page.count("<li>") == 1
    assert f"{len(unjudged)} requirements: <b>{unjudged[0].requirement.id}, " in page
    assert "no case judged this requirement" in page
    assert f"<th>Note</th><td>{run.stop_reason}</td>" in html.header(run)
    assert f"note: {run.stop_reason}" in html.banner(run)


def test_a_run_stopped_for_a_reason_does_not_say_it_was_interrupted():
    """First-hour look (2026-12-05): ``--port sim --address 7`` stopped because no device
    answered at 7, and the header's "Ran to the end" read "no (interrupted or the link
    failed)", neither of which happened."""
    run = ConformanceRun(RunOptions())
    run.stop_reason = "no device answered at address 7"
    run.finish(complete=False)
    head = html.header(run)
    assert "<th>Ran to the end</th><td>no (see Stopped because)</td>" in head, head
    assert f"<th>Stopped because</th><td>{run.stop_reason}</td>" in head
    assert "interrupted or the link failed" not in head


def test_a_diagram_title_states_the_marking_it_draws():
    """Issue 19: a diagram titled "break, 77 ms marking, a!" drew 89.05 ms of marking (the
    link's latency). The title keeps the case's words and says what is drawn."""
    brk = Event(EventKind.BREAK, TOOL, 1.0, 1.013)
    command = 1.013 + 0.08905
    events = [brk, *exchange(command - 0.022, "0!", "0\r\n", 0.009)[1:]]  # its own break dropped
    assert events[1].kind is EventKind.CHAR and abs(events[1].start - command) < 1e-9
    title = timing_diagram.wire_title("break, 77 ms marking, a!", events)
    assert "marking 89.05 ms" in title and "break 13.00 ms" in title, title
    root = parse_svg(timing_diagram.timing_svg(events, title="break, 77 ms marking, a!"))
    assert "marking 89.05 ms" in root.get("aria-label")
    record = CaseRecord("t::r", "r", ("R-7.0-07",), evidence=[("break, 77 ms marking, a!", events)])
    record.findings.append(Finding("R-7.0-07", Verdict.PASS, "answered", measured_ms=9.0))
    page = html.case_html(record)
    assert "Timing: break, 77 ms marking, a! (drawn as on the wire:" in page


def test_the_result_cell_carries_the_verdict_and_ids_do_not_wrap():
    """Issue 19: pytest-html's Result cell said "Skipped" for INCONCLUSIVE and N/A. The cell
    keeps pytest's outcome as its text (pytest-html's filters read it) and draws the verdict."""
    plugin = html.HtmlReportPlugin(SimpleNamespace())
    header = ['<th class="sortable" data-column-type="result">Result</th>', "<th>Test</th>"]
    plugin.pytest_html_results_table_header(header)
    assert header[0].endswith(">Verdict</th>") and header[1] == "<th>Requirements</th>"
    report = SimpleNamespace(sdi12_verdict="N/A", sdi12_requirements=("R-7.1-02", "R-4.0-01"))
    cells = ['<td class="col-result">Skipped</td>', '<td class="col-testId">t</td>']
    plugin.pytest_html_results_table_row(report, cells)
    assert cells[0] == ('<td class="col-result sdi12-verdict v-NA" data-verdict="N/A">Skipped</td>')
    assert cells[1].count('<span class="sdi12-rid">') == 2
    assert "td.col-result.sdi12-verdict::before{content:attr(data-verdict)" in html.STYLE


def _reference_group(events: list[Event]) -> list[list[Event]]:
    """The wire log's grouping as it was written first: a run of characters from one side
    with gaps under two frame times is one line."""
    groups: list[list[Event]] = []
    last: Event | None = None
    for e in events:
        if (
            last is not None
            and e.kind is EventKind.CHAR
            and last.kind is EventKind.CHAR
            and last.origin == e.origin
            and e.start - last.end < 0.0167
        ):
            groups[-1].append(e)
        else:
            groups.append([e])
        last = e
    return groups


def test_the_wire_log_groups_and_counts_parity_as_event_by_event() -> None:
    """The wire log's lines (grouping with the previous event's fields read once, a line's
    characters and parity errors by ``bytes.translate``) are the lines made event by event:
    the same groups, the text with the parity bit dropped, ``Event.parity_ok``'s count of
    errors, over random traffic of both sides with breaks, notes and any 8-bit byte."""
    import random

    rng = random.Random(7)
    for _ in range(200):
        t, events = 0.0, []
        for _ in range(rng.randrange(0, 60)):
            kind = rng.choice([EventKind.CHAR] * 8 + [EventKind.BREAK, EventKind.NOTE])
            t += rng.choice([0.0, 0.001, 0.0166, 0.0167, 0.02, 0.2])
            end = t + (0.0083 if kind is EventKind.CHAR else 0.013)
            wire = rng.randrange(256) if kind is EventKind.CHAR else 0
            text = "a note" if kind is EventKind.NOTE else ""
            events.append(Event(kind, rng.choice([TOOL, DUT]), t, end, wire=wire, text=text))
            t = end
        groups = html._group(events)
        assert groups == _reference_group(events)
        for group in groups:
            if group[0].kind is EventKind.CHAR:
                text = wire_escape(bytes([e.wire & 0x7F for e in group]))
                bad = sum(1 for e in group if not e.parity_ok)
                assert html._line_chars(group) == (text, bad)
