"""The harness's stderr is kept in every report, not only when the harness failed (issue 20,
"Harness edges"): a firmware's own log explains a verdict as often as a crash."""

from __future__ import annotations

import shlex
import sys

from conformance.conduct import run_once
from tests.support.paths import ROOT

HARNESS = ROOT / "examples" / "python" / "sensor_harness.py"


def test_a_harness_that_ran_well_has_its_stderr_in_the_report():
    inner = f"echo firmware log: booted >&2; exec {shlex.quote(sys.executable)} {HARNESS}"
    port = f"exec:sh -c {shlex.quote(inner)}"
    data = run_once(port, keyword="test_acknowledge")
    assert data["run"]["complete"]
    assert "firmware log: booted" in data["run"]["link"]["harness_stderr"]


def test_the_simulated_sensor_has_no_harness_stderr_key():
    data = run_once("sim://", keyword="test_acknowledge")
    assert "harness_stderr" not in data["run"]["link"]
