"""The recorder fault-detection matrix: every faulty golden recorder against the whole
recorder suite, compared with the requirements the fault declares (design.md 5)."""

from __future__ import annotations

from ..matrix import MatrixRow, row_from, run_once
from .faults import RECORDER_FAULTS


def run_recorder_suite(port: str = "sim", extra: tuple[str, ...] = ()) -> dict:
    """Run the recorder suite in this process against ``port``; return verdicts.json."""
    return run_once(port, extra, role="recorder")


def recorder_row(fault: str) -> MatrixRow:
    data = run_recorder_suite(f"sim://?recorder-faults={fault}")
    spec = RECORDER_FAULTS[fault]
    return row_from(fault, spec.violates, data, spec.inconclusive)


def recorder_matrix(faults: list[str] | None = None) -> list[MatrixRow]:
    """One row per recorder fault (all by default); each run takes about a second."""
    return [recorder_row(name) for name in faults or sorted(RECORDER_FAULTS)]
