"""The Arduino logger sketch (examples/arduino/sdi12_logger: the project's tiny logger on a
board, its blocking bus calls made with TinySDI12, its job read from Serial and its values
printed there) in the recorder role: COMPLIANT with the bit rate of its commands judged, and
each faulty twin FAILs exactly the rules of the tool's recorder fault of the same name."""

from __future__ import annotations

import pytest

from conformance.conduct import run_once
from conformance.matrices.sensor_matrix import row_from
from conformance.recorder.faults import RECORDER_FAULTS
from tests.kit.conftest import LOGGER, LOGGER_DECLARATION, TINY_SDI12

# whole recorder suites through a sketch: about 15 s each
pytestmark = pytest.mark.slow

TWINS = ("retries-with-break", "ignores-bad-crc", "ttt-8-bit")


def run_logger(kit_build, *defines: str) -> dict:
    binary = kit_build(LOGGER, (TINY_SDI12,), defines)
    return run_once(f"exec:{binary}", declaration=LOGGER_DECLARATION, role="recorder")


def test_the_logger_sketch_is_compliant_with_its_bit_rate_judged(kit_build):
    data = run_logger(kit_build)
    counts = data["summary"]["counts"]
    assert data["summary"]["verdict"] == "COMPLIANT", counts
    assert counts["INCONCLUSIVE"] == counts["ERROR"] == 0
    verdicts = {r["id"]: r["verdict"] for r in data["requirements"]}
    assert sum(v == "PASS" for v in verdicts.values()) >= 30
    for rid in ("R-4.1-01", "R-4.4-02", "R-7.2-01", "R-7.2-03", "R-4.4.12-07", "R-4.4.7-08"):
        assert verdicts[rid] == "PASS", rid


@pytest.mark.parametrize("fault", TWINS)
def test_a_faulty_logger_twin_fails_exactly_its_requirements(kit_build, fault):
    data = run_logger(kit_build, f"FAULT_{fault.upper().replace('-', '_')}")
    declared = RECORDER_FAULTS[fault]
    row = row_from(fault, declared.violates, data, tuple(declared.inconclusive))
    assert row.exact, (row.missed, row.extra)
    assert data["summary"]["verdict"] == "NON-COMPLIANT"
