"""Root causes named (issue 10): a deviation that drags others after it is shown first, and
the findings it drags name it, in verdicts.json, the console and the HTML read-first list."""

from __future__ import annotations

import pytest

from conformance.catalog import requirement
from conformance.conduct import run_once
from conformance.matrices.recorder_matrix import run_recorder_suite
from conformance.reports.console import noteworthy
from conformance.results import RequirementResult
from conformance.root_causes import DRAGS, link, reading_order
from conformance.verdicts import Finding, Verdict


def result(rid: str, verdict: Verdict, detail: str = "x") -> RequirementResult:
    found = Finding(rid, verdict, detail, observed=1, evidence=[detail])
    return RequirementResult(requirement(rid), verdict, [found], [])


def test_a_failed_root_names_itself_in_what_it_drags():
    root = result("R-7.0-07", Verdict.FAIL, "no reply 90 ms after the break at t=3.210 s")
    dragged = result("R-7.0-05", Verdict.FAIL)
    other = result("R-4.4.1-01", Verdict.FAIL)
    assert link([other, dragged, root]) == [root]
    assert dragged.consequence_of == "R-7.0-07"
    assert "probably a consequence of R-7.0-07 at t=3.210 s" in dragged.findings[0].detail
    assert other.consequence_of is None
    ordered = [r.requirement.id for r in reading_order([other, dragged, root])]
    assert ordered == ["R-7.0-07", "R-7.0-05", "R-4.4.1-01"]


def test_no_root_without_its_own_fail():
    dragged = result("R-7.0-05", Verdict.FAIL)
    assert link([result("R-7.0-07", Verdict.PASS), dragged]) == []
    assert dragged.consequence_of is None


def test_every_root_and_dragged_rule_is_in_the_catalog():
    for root, (dragged, why) in DRAGS.items():
        assert requirement(root) and why
        assert all(requirement(rid) for rid in dragged)


def _first_rows(data: dict) -> list[str]:
    return [which for _, which, _ in noteworthy(data)]


def test_a_timing_fault_shows_its_root_first_and_its_collateral_names_it():
    """slow-wake: the sensor needs 110 ms to wake (R-7.0-07), so the command 9 ms after the
    break goes unanswered (R-7.0-05): a real FAIL, linked to its cause."""
    data = run_once("sim://?faults=slow-wake")
    verdicts = {r["id"]: r for r in data["requirements"]}
    assert verdicts["R-7.0-05"]["consequence_of"] == "R-7.0-07"
    assert any(
        "probably a consequence of R-7.0-07" in f["detail"]
        for f in verdicts["R-7.0-05"]["findings"]
        if f["verdict"] == "FAIL"
    )
    assert _first_rows(data)[:2] == ["R-7.0-07", "R-7.0-05"]


@pytest.mark.slow
def test_a_recorder_retry_over_a_reply_is_the_root_of_its_broken_command():
    data = run_recorder_suite("sim://?recorder-faults=talks-over-reply")
    verdicts = {r["id"]: r for r in data["requirements"]}
    assert verdicts["R-7.0-13"]["consequence_of"] == "R-7.2-06"
    assert _first_rows(data)[:2] == ["R-7.2-06", "R-7.0-13"]


def test_a_sensors_break_before_its_reply_is_its_own_root_not_a_late_replys():
    """break-before-reply: the sensor's break right after the command ends R-7.0-09's marking
    (FAIL) and its reply comes at 20.5 ms (R-7.0-10 FAIL). The R-7.0-09 FAIL does not come
    from a late reply running into a retry, so it names no root."""
    data = run_once("sim://?faults=break-before-reply")
    verdicts = {r["id"]: r for r in data["requirements"]}
    assert verdicts["R-7.0-09"]["verdict"] == "FAIL"
    assert verdicts["R-7.0-10"]["verdict"] == "FAIL"
    assert verdicts["R-7.0-09"]["consequence_of"] is None
    assert not any("consequence of" in f["detail"] for f in verdicts["R-7.0-09"]["findings"])
