"""The console as a user sees it: plain lines in a CI log, a live display on a terminal.

Both runs go through the real command line in-process, with the console pointed at a buffer
that either is or is not a terminal.
"""

from __future__ import annotations

import io
import json
import re
from pathlib import Path

import pytest
from rich.console import Console

from conformance import cli
from conformance.reports.console import REASON_WIDTH, _reason, one_line

FAULTY = "sim://?faults=no-service-request"
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def run_cli(
    monkeypatch, tmp_path: Path, port: str, *extra: str, terminal: bool
) -> tuple[int, str, dict]:
    buffer = io.StringIO()
    console = Console(file=buffer, force_terminal=terminal, width=100, color_system="standard")
    monkeypatch.setattr(cli, "make_console", lambda **_: console)
    code = cli.main(["--port", port, "--report-dir", str(tmp_path), *extra])
    data = json.loads((tmp_path / "verdicts.json").read_text(encoding="utf-8"))
    return code, buffer.getvalue(), data


def test_plain_output_has_one_line_per_case_and_every_finding_to_read(monkeypatch, tmp_path):
    code, out, data = run_cli(monkeypatch, tmp_path, FAULTY, terminal=False)
    assert code == cli.EXIT_NON_COMPLIANT
    assert "\x1b" not in out, "no escape codes in a log"
    lines = out.splitlines()
    total = len(data["tests"])
    assert lines[0] == f"running {total} conformance cases"
    progress = [line for line in lines if re.match(rf"\[\s*\d+/{total}\] ", line)]
    assert len(progress) == total
    assert any(
        re.match(r"\[\s*\d+/\d+\] FAIL\s+test_service_request  R-4\.4\.6-02: 0M!", line)
        for line in progress
    ), progress
    assert all(len(line) <= REASON_WIDTH + 60 for line in lines), "reasons stay on one line"
    for r in data["requirements"]:
        if r["verdict"] in ("FAIL", "INCONCLUSIVE", "WARN", "ERROR"):
            assert any(line.startswith(f"{r['verdict']:<12} {r['id']}: ") for line in lines), r
    assert "verdict: NON-COMPLIANT" in lines
    assert f"report: {tmp_path / 'report.html'}" in lines


@pytest.mark.slow
def test_plain_output_of_a_clean_run_lists_nothing_to_read(monkeypatch, tmp_path):
    code, out, data = run_cli(monkeypatch, tmp_path, "sim", terminal=False)
    assert code == cli.EXIT_COMPLIANT
    assert not re.search(r"^(FAIL|ERROR|INCONCLUSIVE|WARN) ", out, re.MULTILINE)
    assert "106 testable requirements judged" in out
    assert out.rstrip().splitlines()[-3] == "verdict: COMPLIANT"


@pytest.mark.slow
def test_terminal_shows_progress_failures_live_and_a_summary_table(monkeypatch, tmp_path):
    code, out, data = run_cli(monkeypatch, tmp_path, FAULTY, terminal=True)
    assert code == cli.EXIT_NON_COMPLIANT
    assert "judging" in out, "the progress bar was drawn"
    text = ANSI.sub("", out).replace("\r", "\n")
    lines = text.splitlines()
    assert any(line.startswith("FAIL         test_service_request  R-4.4.6-02") for line in lines)
    assert all(len(line) <= 100 for line in lines), "nothing wraps past the terminal width"
    assert "Read first" in text
    failing = [r["id"] for r in data["requirements"] if r["verdict"] in ("FAIL", "INCONCLUSIVE")]
    for rid in failing:
        assert re.search(rf"│ {re.escape(rid)}\s+│ \S", text), rid
    counts = data["summary"]["counts"]
    order = ("ERROR", "FAIL", "INCONCLUSIVE", "WARN", "PASS", "N/A")
    tally = ", ".join(f"{counts[v]} {v}" for v in order if counts[v])
    assert f" NON-COMPLIANT   {tally}" in text
    assert f"report: {tmp_path / 'report.html'}" in text


@pytest.mark.slow
def test_a_selection_is_a_partial_run_judged_on_what_it_selected(monkeypatch, tmp_path):
    code, out, data = run_cli(monkeypatch, tmp_path, "sim", "-k", "crc", terminal=False)
    left_out = [r["id"] for r in data["requirements"] if not r["selected"]]
    testable = sum(1 for r in data["requirements"] if r["testable"])
    assert code == cli.EXIT_COMPLIANT and len(left_out) > 4
    assert not [r for r in data["requirements"] if r["verdict"] == "INCONCLUSIVE"]
    assert data["run"]["partial"] is True and data["run"]["selection"] == "-k crc"
    judged = testable - len(left_out)
    assert f"partial run (-k crc): {judged} selected testable requirements judged" in out
    assert f"{len(left_out)} of {testable} not selected" in out
    assert " N/A, " not in out.split("partial run", 1)[1]  # left out: "not selected", only
    assert "verdict: COMPLIANT (partial run: the selected requirements only)" in out
    assert sum(data["summary"]["counts"].values()) == len(data["requirements"]) - len(left_out)


@pytest.mark.parametrize(
    ("text", "width", "expected"),
    [
        ("short", 10, "short"),
        ("a\nmulti  line\treason", 40, "a multi line reason"),
        ("x" * 30, 10, "xxxxxxx..."),
    ],
)
def test_one_line(text, width, expected):
    assert one_line(text, width) == expected


@pytest.mark.slow
def test_judged_counts_verdicts_on_the_device_not_na():
    """Issue 10: a v1.3 run judged 77 rules; the 29 that bind v1.4 only are N/A, said apart."""
    from conformance.conduct import run_once
    from conformance.reports.console import _coverage

    line = _coverage(run_once("sim://?version=1.3"))
    assert line.startswith("77 of 106 testable requirements judged, 29 N/A")


def test_a_real_link_run_ends_with_its_bus_time_and_efficiency():
    from conformance.reports.console import bus_line

    bus = {"bus_lower_bound_s": 273.546, "wall_s": 288.915, "efficiency": 0.947}
    real = {"run": {"bus": bus, "link": {"kind": "rfc2217", "bench": {"echo": False}}}}
    # 0.947, not "0.95": two decimals read as a 0.95 target met
    assert (
        bus_line(real) == "bus time: at least 273.5 s on the wire, 288.9 s wall (efficiency 0.947)"
    )
    sim = {"run": {"bus": {**bus, "wall_s": None}, "link": {"kind": "sim"}}}
    assert bus_line(sim) is None  # a virtual clock's time is no one's wall time
    recording = {"run": {"bus": bus, "link": {"kind": "capture sr"}}}
    assert bus_line(recording) is None


def test_the_count_of_further_findings_agrees_in_number():
    """First-hour look (2026-12-05): abort-keeps-old-data's R-5.3-01 line ended "(+1 more
    findings)"."""

    def requirement(n: int) -> dict:
        found = [{"verdict": "FAIL", "detail": f"d{i}"} for i in range(n)]
        return {"verdict": "FAIL", "findings": [*found, {"verdict": "PASS", "detail": "ok"}]}

    assert _reason(requirement(1)) == "d0"
    assert _reason(requirement(2)) == "d0 (+1 more finding)"
    assert _reason(requirement(3)) == "d0 (+2 more findings)"
