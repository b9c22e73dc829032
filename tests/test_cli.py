"""The command line as a user runs it: exit codes, the four output files, errors to act on."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from conformance.catalog import for_role


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "conformance.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )


# The default selection's CLI run on sim is test_verdicts_contract's clean run (the same
# command); these two repeat it in the full run only.
@pytest.fixture(scope="module")
def clean(tmp_path_factory) -> tuple[subprocess.CompletedProcess[str], Path]:
    out = tmp_path_factory.mktemp("clean")
    return run("--port", "sim", "--role", "sensor", "--report-dir", str(out)), out


@pytest.mark.slow
def test_clean_simulated_sensor_is_compliant(clean):
    proc, out = clean
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "COMPLIANT" in proc.stdout
    for name in ("report.html", "verdicts.json", "junit.xml", "transcript.jsonl"):
        assert (out / name).stat().st_size > 0, name


@pytest.mark.slow
def test_judged_count_equals_testable_sensor_requirements(clean):
    proc, out = clean
    data = json.loads((out / "verdicts.json").read_text())
    testable = [r for r in for_role("sensor") if r.testable("sensor")]
    judged = [r for r in data["requirements"] if r["testable"]]
    assert len(judged) == len(testable) == 106
    assert f"{len(testable)} testable requirements judged" in proc.stdout
    assert all(r["verdict"] in ("PASS", "N/A") for r in judged)
    assert data["summary"]["counts"]["FAIL"] == data["summary"]["counts"]["WARN"] == 0


@pytest.mark.slow
def test_a_fault_makes_the_run_non_compliant(tmp_path):
    proc = run("--port", "sim://?faults=no-service-request", "--report-dir", str(tmp_path))
    assert proc.returncode == 1, proc.stdout + proc.stderr
    data = json.loads((tmp_path / "verdicts.json").read_text())
    failed = {r["id"] for r in data["requirements"] if r["verdict"] == "FAIL"}
    assert failed == {"R-4.4.6-02"}
    assert "R-4.4.6-02" in proc.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--port", "sim://?faults=no-such-fault"), "unknown fault"),
        (("--port", "sim://?version=2.0"), "1.3 or 1.4"),
        (("--sdi-version", "1.7"), "unsupported SDI-12 version"),
        (("--declaration", "/nonexistent.toml"), "does not exist"),
        (("--role", "recorder", "--port", "sim://?recorder-faults=x"), "is not a recorder fault"),
        (("--port", "/dev/ttyUSB9"), "serial port /dev/ttyUSB9 does not exist"),
        (("--bogus",), "unrecognized arguments"),
        # first-hour look (2026-12-05): "unknown sim parameters ['fault']", a Python list
        (("--port", "sim://?fault=wrong-crc"), "sim parameter(s) fault (did you mean faults?)"),
    ],
)
def test_usage_errors_exit_4_with_a_reason(tmp_path, args, message):
    proc = run(*args, "--report-dir", str(tmp_path))
    assert proc.returncode == 4
    assert message in proc.stdout + proc.stderr


def test_list_shows_every_testable_requirement_covered():
    proc = run("list", "--role", "sensor")
    assert proc.returncode == 0
    assert "106/106 testable requirements covered by a case" in proc.stdout.replace("\n", " ")


def test_version_and_help():
    assert run("--version").stdout.startswith("sdi12-conform ")
    helped = run("--help")
    assert helped.returncode == 0 and "exit codes" in helped.stdout


@pytest.mark.slow
def test_version_1_3_sensor_is_compliant(tmp_path):
    proc = run("--port", "sim://?version=1.3&address=5", "--report-dir", str(tmp_path))
    assert proc.returncode == 0, proc.stdout
    data = json.loads((tmp_path / "verdicts.json").read_text())
    assert data["dut"]["sdi12_version"] == "1.3" and data["dut"]["address"] == "5"


def test_a_reader_that_goes_away_leaves_the_run_to_finish(tmp_path):
    """``sdi12-conform ... | head -2``: the pipe closes after two lines. The run goes on to
    its end and its reports, with the verdict's exit code; before, rich ended the process
    from inside a pytest hook (INTERNALERROR tracebacks, exit 3, no report)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "conformance.cli", "--port", "sim://?faults=wrong-crc",
         "--report-dir", str(tmp_path)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.readline()
    proc.stdout.close()  # the reader is gone: every later write meets a broken pipe
    stderr = proc.stderr.read()
    assert proc.wait(timeout=120) == 1, stderr  # NON-COMPLIANT, as the run found
    assert "INTERNALERROR" not in stderr and "Traceback" not in stderr, stderr
    data = json.loads((tmp_path / "verdicts.json").read_text())
    assert data["summary"]["verdict"] == "NON-COMPLIANT" and data["run"]["complete"]


def test_the_process_ends_at_once_only_when_no_thread_would_be_waited_for():
    """A finished run's process skips the interpreter's teardown (about 0.15 s), but never
    while a non-daemon thread is alive: Python's exit would have waited for it."""
    import threading

    from conformance.cli import _exit_at_once

    release = threading.Event()
    worker = threading.Thread(target=release.wait)
    worker.start()
    try:
        assert _exit_at_once(0) is None  # returned: the usual exit will join the thread
    finally:
        release.set()
        worker.join()
