"""The suite's own quality metric (design.md 5): every emulator fault is caught by exactly
the requirements it declares (FAIL/WARN, and INCONCLUSIVE only where the fault declares that
collateral), the clean emulator is COMPLIANT at v1.3 and v1.4, and every testable sensor
requirement is exercised by at least one fault. The runs of every fault of a measured timing
rule and of a fixed third of the others are also
judged through a logic-analyzer capture of themselves (issue 11: ``export`` to .sr, ``judge``
the capture): the same verdicts, or a capture deciding what the live run left INCONCLUSIVE
(``SDI12_MATRIX_CAPTURE=all`` takes every fault, as ``sdi12-conform matrix`` does; a second
suite run per fault is what CI's budget cannot hold for all 125).

One test per fault, so a failure names its fault; the rows are held by
``test_sensor_matrix_rows_<n>.py`` (:mod:`tests.matrices.sensor_rows`: split so several
pytest-xdist workers share them), each module making the rows of its selected faults once
(``-k some-fault`` runs one). This module holds the matrix's other tests.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from conformance.catalog import for_role
from conformance.conduct import run_once
from conformance.emulator import FAULTS
from conformance.matrices.roundtrip import in_capture_sample, in_default_sample
from tests.matrices.sensor_rows import SHARDS, SINGLE, shard_faults


def test_the_rows_modules_hold_every_fault_once():
    """Each single-sensor fault has its row in exactly one rows module, one test each."""
    held = [f for shard in range(1, SHARDS + 1) for f in shard_faults(shard)]
    assert sorted(held) == SINGLE and len(held) == len(set(held))
    for weigh in (lambda f: True, in_default_sample):  # all rows, the captured ones
        sizes = [sum(map(weigh, shard_faults(shard))) for shard in range(1, SHARDS + 1)]
        assert max(sizes) - min(sizes) <= 1
    rows_modules = sorted(Path(__file__).parent.glob("test_sensor_matrix_rows_*.py"))
    assert [m.stem.rsplit("_", 1)[1] for m in rows_modules] == [
        str(n) for n in range(1, SHARDS + 1)
    ]
    for n, module in enumerate(rows_modules, 1):
        assert f"shard_params({n})" in module.read_text()


def test_the_matrix_is_large():
    assert len(FAULTS) >= 60
    sampled = [f for f in FAULTS if in_capture_sample(f)]
    if os.environ.get("SDI12_MATRIX_CAPTURE") == "all":  # asked for every fault's capture
        assert len(sampled) == len(FAULTS)
    else:
        assert len(FAULTS) / 4 < len(sampled) < len(FAULTS) / 2  # about a third
    # every fault of a rule judged on a measured figure goes through its capture
    assert in_capture_sample("response-too-late") and in_capture_sample("inter-char-gap")


@pytest.mark.parametrize("version", [pytest.param("1.3", marks=pytest.mark.slow), "1.4"])
def test_clean_emulator_is_compliant_with_no_fail_or_warn(version):
    data = run_once(f"sim://?version={version}")
    assert data["summary"]["verdict"] == "COMPLIANT"
    counts = data["summary"]["counts"]
    # on the virtual-time bus every timing rule gets a definite verdict
    assert counts["FAIL"] == counts["WARN"] == counts["INCONCLUSIVE"] == counts["ERROR"] == 0
    judged = [r for r in data["requirements"] if r["testable"]]
    assert len(judged) == 106


def test_every_testable_sensor_requirement_is_exercised_by_a_fault():
    declared = {rid for fault in FAULTS.values() for rid in fault.violates}
    testable = {r.id for r in for_role("sensor") if r.testable("sensor")}
    assert sorted(testable - declared) == []
