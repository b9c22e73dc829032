"""The production profile (issue 23, item 5): an end-of-line test short on the bus, its
report folder named by the sensor's serial number, a fault of what it checks still caught."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from conformance.cli import main
from conformance.profiles import PRODUCTION
from conformance.report_folder import LOCK_NAME, named_by_serial


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "conformance.cli", *args],
        capture_output=True, text=True, timeout=300, cwd=cwd,
    )  # fmt: skip


def test_a_production_run_is_short_named_by_serial_and_says_what_it_tried(tmp_path):
    proc = _cli("--port", "sim", "--profile", "production", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    (folder,) = (tmp_path / "reports").iterdir()
    assert folder.name.endswith("-SN0001"), folder.name  # the emulator's serial, from aI!
    assert not (folder / LOCK_NAME).exists()
    assert f"report: reports/{folder.name}/report.html" in proc.stdout
    data = json.loads((folder / "verdicts.json").read_text())
    assert data["summary"]["verdict"] == "COMPLIANT" and data["run"]["partial"]
    assert data["run"]["selection"] == "--profile production"
    ran = {t.split("::")[-1] for r in data["requirements"] for t in r["tests"]}
    assert ran == set(PRODUCTION.cases)
    assert data["run"]["bus"]["bus_lower_bound_s"] < 20  # the budget per sensor
    assert any("--profile production" in a and "aM!" in a for a in data["dut"]["assumptions"])
    judged = {r["id"] for r in data["requirements"] if r["verdict"] == "PASS"}
    assert {"R-4.4.2-01", "R-4.4.12-05", "R-7.0-09", "R-4.4.7-01"} <= judged


def test_a_fault_the_profile_checks_fails_it(tmp_path):
    out = tmp_path / "run"
    code = main(
        ["--port", "sim://?faults=wrong-crc", "--profile", "production", "--report-dir", str(out)]
    )
    assert code == 1
    data = json.loads((out / "verdicts.json").read_text())
    failed = {r["id"] for r in data["requirements"] if r["verdict"] == "FAIL"}
    assert failed == {"R-4.4.12-05"}
    assert out.exists()  # a folder the user named keeps its name


def test_the_profile_is_for_sensors_and_its_plan_is_its_own(tmp_path):
    proc = _cli("--port", "sim", "--role", "recorder", "--profile", "production", cwd=tmp_path)
    assert proc.returncode == 4 and "selects sensor cases" in proc.stderr, proc.stderr
    plan = tmp_path / "plan.json"
    assert main(["plan", "--profile", "production", "--format", "json", "-o", str(plan)]) == 0
    data = json.loads(plan.read_text())
    assert len(data["cases"]) == len(PRODUCTION.cases) and data["expected_bus_s"] < 20
    assert data["selection"]["profile"] == "production"


def test_a_folder_is_named_by_serial_only_when_one_is_there_and_free(tmp_path):
    run = tmp_path / "20260101-120000-sensor"
    run.mkdir()
    assert named_by_serial(run, None, "sensor") == run
    assert named_by_serial(run, " / ", "sensor") == run  # nothing usable in it
    renamed = named_by_serial(run, "SN 42/7", "sensor")
    assert renamed.name == "20260101-120000-SN_42_7" and renamed.is_dir() and not run.exists()
    other = tmp_path / "20260101-120000-sensor"
    other.mkdir()
    (renamed / "verdicts.json").write_text("{}")  # the name is taken by a finished run
    assert named_by_serial(other, "SN 42/7", "sensor") == other


def test_a_production_run_replays_to_its_own_verdicts(tmp_path):
    """``judge`` of a production run's folder repeats its stimuli (the profile is in its
    run-options note), so the replay gets the run's verdicts, not a divergence."""
    out = tmp_path / "run"
    assert main(["--port", "sim", "--profile", "production", "--report-dir", str(out)]) == 0
    again = tmp_path / "again"
    assert main(["judge", str(out), "--report-dir", str(again)]) == 0
    verdicts = [json.loads((d / "verdicts.json").read_text()) for d in (out, again)]
    a, b = ({r["id"]: r["verdict"] for r in v["requirements"]} for v in verdicts)
    assert a == b
