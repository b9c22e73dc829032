"""The recorder fault-detection matrix: every faulty golden recorder against the whole
recorder suite, compared with the requirements the fault declares (design.md 5)."""

from __future__ import annotations

import json
import tempfile
from importlib import resources
from pathlib import Path

from ..matrix import BAD, MatrixRow
from .faults import RECORDER_FAULTS


def run_recorder_suite(port: str = "sim", extra: tuple[str, ...] = ()) -> dict:
    """Run the recorder suite in this process against ``port``; return verdicts.json."""
    import pytest

    with tempfile.TemporaryDirectory(prefix="sdi12-recorder-") as tmp:
        args = [
            "-c",
            str(resources.files("conformance") / "suite.ini"),
            "--rootdir",
            tmp,
            "-p",
            "no:cacheprovider",
            "-p",
            "no:terminal",
            "-p",
            "no:html",
            "--pyargs",
            "testcases.recorder",
            "--sdi12-role",
            "recorder",
            "--sdi12-port",
            port,
            "--sdi12-report-dir",
            tmp,
            *extra,
        ]
        pytest.main(args)
        return json.loads((Path(tmp) / "verdicts.json").read_text(encoding="utf-8"))


def recorder_row(fault: str) -> MatrixRow:
    data = run_recorder_suite(f"sim://?recorder-faults={fault}")
    reqs = data["requirements"]
    return MatrixRow(
        fault,
        RECORDER_FAULTS[fault].violates,
        tuple(r["id"] for r in reqs if r["verdict"] in BAD),
        data["summary"]["verdict"],
        tuple(
            f"{r['id']}={r['verdict']}" for r in reqs if r["verdict"] in ("INCONCLUSIVE", "ERROR")
        ),
        tuple(r["id"] for r in reqs if r["verdict"] == "FAIL"),
    )


def recorder_matrix(faults: list[str] | None = None) -> list[MatrixRow]:
    """One row per recorder fault (all by default); each run takes about a second."""
    return [recorder_row(name) for name in faults or sorted(RECORDER_FAULTS)]
