"""The measurement-count findings name their command once (first-hour look, 2026-12-05).

The judge leads each violation with the command it is about; the count rules also put the
command in their own text, so a v1.3 concurrent sensor read "0C!: 0C! announced 25 values;
the 2000 v1.3 text allows 20" and a zero count "0M!: 0M! announced zero values"."""

from __future__ import annotations

import re

import pytest

from conformance.conduct import run_once
from conformance.emulator import FAULTS
from conformance.matrices.sensor_matrix import fault_port


@pytest.mark.parametrize(
    ("fault", "rid", "words"),
    [
        ("v13-concurrent-over-20", "R-4.4.7-03", "announced 25 values"),
        ("measure-count-zero", "R-4.4.5-02", "announced zero values"),
    ],
)
def test_a_count_finding_names_its_command_once(fault, rid, words):
    port = fault_port((fault, (), getattr(FAULTS[fault], "version", None) or "14", ()))
    data = run_once(port, keyword="measurement_reply or concurrent_reply")
    (req,) = [r for r in data["requirements"] if r["id"] == rid]
    details = [f["detail"] for f in req["findings"] if words in f["detail"]]
    assert details, req["findings"]
    for detail in details:
        assert not re.search(r"(\S+!): \1 ", detail), detail
        assert f"!: {words}" in detail, detail  # led by its command, once
