"""``sdi12-conform diff A B`` and ``--baseline`` (issue 24, item 2): the firmware team's gate
"nothing got worse than the last good run". The comparison is a pure function over two
verdicts.json documents; the live tests diff the clean simulated sensor against faulty ones
and check that exactly each fault's requirements come out worse."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.conduct import run_into, run_once
from conformance.emulator import FAULTS
from conformance.matrices.combinations import combo_port
from conformance.reports.diff import DiffError, diff_runs, load_run, worse


def run(*reqs: tuple[str, str, list[dict]], role: str = "sensor", ident: str = "x") -> dict:
    return {
        "schema": "sdi12-conform/verdicts/1",
        "run": {"role": role},
        "dut": {"address": "0", "identification": ident, "sdi12_version": "1.4"},
        "requirements": [
            {"id": rid, "verdict": v, "selected": True, "findings": fs} for rid, v, fs in reqs
        ],
    }


def finding(verdict: str, detail: str, **timing: float) -> dict:
    return {"verdict": verdict, "detail": detail, "test": "t::c", **timing}


def test_a_verdict_that_got_worse_is_worse_and_one_that_got_better_is_not():
    a = run(("R-4.2-03", "PASS", []), ("R-7.0-10", "FAIL", [finding("FAIL", "late")]))
    b = run(("R-4.2-03", "INCONCLUSIVE", []), ("R-7.0-10", "PASS", []))
    changes = diff_runs(a, b)
    verdicts = {c.requirement: c for c in changes if c.kind == "verdict"}
    assert verdicts["R-4.2-03"].worse and not verdicts["R-7.0-10"].worse
    assert verdicts["R-7.0-10"].better
    assert worse(changes)
    assert not worse(diff_runs(b, b))


def test_na_and_pass_are_equally_good():
    assert not worse(diff_runs(run(("R-5.1-01", "PASS", [])), run(("R-5.1-01", "N/A", []))))


def test_a_new_deviation_under_a_rule_already_failing_is_worse():
    old = [finding("FAIL", "reply '0' has no CR LF")]
    new = [*old, finding("FAIL", "reply '0+1' has two values where 3 were announced")]
    changes = diff_runs(run(("R-4.2-03", "FAIL", old)), run(("R-4.2-03", "FAIL", new)))
    (added,) = [c for c in changes if c.kind == "finding-added"]
    assert added.worse and "two values" in added.text


def test_a_long_detail_is_cut_with_an_ellipsis_not_bare():
    """First-hour look (2026-12-05): diffing the clean sim against no-service-request listed
    "R-4.4.6-02: PASS -> FAIL (... (the recorder had to wait it out and)": the detail cut at
    160 characters with nothing to say so, the verdict line and the finding line alike."""
    long = "0M!: no service request within ttt=2 s (the recorder had to wait it out). " * 5
    changes = diff_runs(
        run(("R-4.4.6-02", "PASS", [])), run(("R-4.4.6-02", "FAIL", [finding("FAIL", long)]))
    )
    texts = {c.kind: c.text for c in changes}
    assert texts["verdict"].endswith("...)") and len(texts["verdict"]) < len(long)
    assert texts["finding-added"].endswith("...")
    short = run(("R-4.4.6-02", "FAIL", [finding("FAIL", "late")]))
    assert [c.text for c in diff_runs(run(("R-4.4.6-02", "PASS", [])), short)][0].endswith("(late)")


def test_the_same_deviation_with_other_numbers_is_not_new():
    a = run(("R-4.4.8-03", "FAIL", [finding("FAIL", "4 values were returned for 9 announced")]))
    b = run(("R-4.4.8-03", "FAIL", [finding("FAIL", "3 values were returned for 9 announced")]))
    assert diff_runs(a, b) == []


def test_a_timing_figure_is_listed_only_when_it_moved_by_more_than_its_uncertainty():
    def timed(measured: float, unc: float) -> dict:
        f = finding("PASS", "ok (≤ 15.40 ms)", measured_ms=measured, limit_ms=15.4)
        return run(("R-7.0-10", "PASS", [{**f, "uncertainty_ms": unc}]))

    assert diff_runs(timed(9.4, 1.0), timed(10.9, 1.0)) == []  # 1.5 ms inside ±2 ms
    (moved,) = diff_runs(timed(9.4, 0.1), timed(15.2, 0.1))
    assert moved.kind == "margin" and not moved.worse
    assert "margin 6.00 -> 0.20 ms, closer to it" in moved.text


def test_a_changed_identification_is_listed_not_worse():
    (c,) = diff_runs(run(ident="014A"), run(ident="014B"))
    assert c.kind == "identification" and not c.worse


def test_runs_of_different_roles_and_unreadable_files_are_refused(tmp_path: Path):
    with pytest.raises(DiffError, match="recorder"):
        diff_runs(run(), run(role="recorder"))
    with pytest.raises(DiffError, match="no verdicts.json"):
        load_run(tmp_path)
    (tmp_path / "verdicts.json").write_text("{}", encoding="utf-8")
    with pytest.raises(DiffError, match="schema"):
        load_run(tmp_path)


# -- live: the clean simulated sensor against faulty ones -----------------------------------


class CleanRuns(dict):
    """The clean sim's verdicts per version, each run once and only if a fault needs it."""

    def __missing__(self, version: str) -> dict:
        self[version] = run_once(f"sim://?version={version[0]}.{version[1]}")
        return self[version]


@pytest.fixture(scope="module")
def clean() -> CleanRuns:
    return CleanRuns()


def worse_requirements(clean: dict, fault: str) -> set[str]:
    port = combo_port((fault,))
    version = port.rsplit("version=", 1)[1].replace(".", "")
    return {c.requirement for c in diff_runs(clean[version], run_once(port)) if c.worse}


#: one fault each of framing, addressing, measurement state and high volume (CI time is
#: budgeted: the fault matrix itself proves every fault's requirements)
SAMPLE = [
    "missing-crlf",
    "answers-foreign-address",
    "abort-keeps-old-data",
    "high-volume-two-digit-count",
]


@pytest.mark.parametrize(
    "fault",
    ["response-too-late", *(pytest.param(f, marks=pytest.mark.matrix) for f in SAMPLE)],
)
def test_diff_from_the_clean_sensor_names_exactly_the_fault_s_requirements(fault, clean):
    declared = set(FAULTS[fault].violates)
    names = worse_requirements(clean, fault)
    assert declared <= names <= declared | set(FAULTS[fault].inconclusive), (names, declared)


def test_the_exit_codes_of_diff_and_baseline(tmp_path: Path, capsys):
    good, bad = tmp_path / "good", tmp_path / "bad"
    run_into(good, "sim://")
    run_into(bad, "sim://?faults=response-too-late")
    assert main(["diff", str(good), str(bad)]) == 1
    assert "R-7.0-10: PASS -> FAIL" in capsys.readouterr().out
    assert main(["diff", str(bad), str(good / "verdicts.json")]) == 0
    assert main(["diff", str(good), str(tmp_path / "missing")]) == 4
    capsys.readouterr()
    assert main(["diff", str(good), str(bad), "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["worse"] is True
    # --baseline: a NON-COMPLIANT device that gained nothing new passes the gate
    again = tmp_path / "again"
    port = "sim://?faults=response-too-late"
    assert main(["--port", port, "--report-dir", str(again), "--baseline", str(bad)]) == 0
    assert json.loads((again / "baseline-diff.json").read_text())["worse"] is False
    worse_run = tmp_path / "worse"
    assert main(["--port", port, "--report-dir", str(worse_run), "--baseline", str(good)]) == 1
    # a baseline that cannot be read is a usage error before the run
    assert main(["--port", "sim", "--report-dir", str(tmp_path / "x"), "--baseline", "nope"]) == 4
    assert not (tmp_path / "x" / "verdicts.json").exists()
