"""The suite's own quality metric (design.md 5): every emulator fault is caught by exactly
the requirements it declares, the clean emulator is COMPLIANT at v1.3 and v1.4, and every
testable sensor requirement is exercised by at least one fault."""

from __future__ import annotations

import pytest

from conformance.catalog import for_role
from conformance.emulator import FAULTS
from conformance.matrix import fault_matrix, run_once


@pytest.fixture(scope="module")
def matrix():
    return fault_matrix(processes=2)


def test_every_fault_is_caught_by_exactly_its_requirements(matrix):
    wrong = [
        f"{r.fault}: missed {list(r.missed)}, also flagged {list(r.extra)}"
        for r in matrix
        if not r.exact
    ]
    assert not wrong, "\n".join(wrong)
    # a FAIL makes the run NON-COMPLIANT; a fault of a SHOULD rule only warns
    assert all((r.verdict == "NON-COMPLIANT") == bool(r.failed) for r in matrix)
    assert len(matrix) == len(FAULTS) >= 60


@pytest.mark.parametrize("version", ["1.3", "1.4"])
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
