"""The wake-up rules probe two wakes in a row (``test_7_timing._at_two_wakes``).

A sensor that needs 110 ms after every second break only (fault slow-wake-every-other)
answered the one probe R-7.0-05 (9 ms of marking) and R-7.0-07 (90 ms after the break) each
sent, after a break it woke from at once: both PASSed and the run was COMPLIANT (docs/kit.md,
thirty-fourth round). Whichever break the first probe follows, the second follows the other.
"""

from __future__ import annotations

import pytest

from conformance.conduct import run_once

WAKE_CASES = "test_ready_within_100ms_of_break or test_marking_after_break"


def _verdicts(port: str, keyword: str) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in run_once(port, keyword=keyword)["requirements"]}


@pytest.mark.parametrize(
    "keyword",
    [
        WAKE_CASES,  # the first probe after the run's first breaks
        # one more break before them (the identification's own), so the other parity
        "test_identification or " + WAKE_CASES,
    ],
)
def test_a_sensor_slow_to_wake_every_other_time_fails_both_rules(keyword):
    found = _verdicts("sim://?faults=slow-wake-every-other", keyword)
    assert found["R-7.0-07"] == "FAIL"
    assert found["R-7.0-05"] == "FAIL"


def test_a_sensor_that_always_wakes_at_once_still_passes_both():
    found = _verdicts("sim://", WAKE_CASES)
    assert found["R-7.0-07"] == "PASS"
    assert found["R-7.0-05"] == "PASS"
