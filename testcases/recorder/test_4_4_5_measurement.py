"""Sections 4.4.5-4.4.6 and 7.1: how a recorder waits for the data of aM!-type measurements."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.breaks import judge_break_rules
from conformance.judges.recorder.measurements import observed_measurements
from conformance.judges.recorder.waits import judge_measure_waits

from ._helpers import line_of

requirements = pytest.mark.requirements
WAIT_SCENARIOS = (
    "service-request",
    "no-service-request",
    "ttt-zero",
    "ttt-over-255",
    "two-sensors",
    "families",
)


@requirements("R-4.4.5-04", "R-4.4.5-05", "R-4.4.5-06", "R-4.4.5-07")
@pytest.mark.preconditions("recorder")
def test_waiting_for_the_service_request(recorder, case):
    """After 'atttn' the recorder leaves the line alone until the service request or ttt,
    then asks for aD0! at once (after a break when ttt ran out), and talks to no other sensor
    until the data are in."""
    case.expect(
        "aD0! not before the service request / ttt; within 0.5 s after it; a break first when "
        "ttt ran out; aD0! at once for ttt = 000 (SHOULD); no command to another address "
        "until the last D reply"
    )
    line = line_of(recorder, case, *WAIT_SCENARIOS)
    taken = observed_measurements(line, recorder.uncertainty)
    case.extend(judge_measure_waits(taken, recorder.uncertainty, line.stalls))


@requirements("R-7.1-01")
@pytest.mark.preconditions("recorder")
def test_d0_after_service_request(recorder, case):
    """aD0! may follow a service request without a break only within 87 ms."""
    case.expect("aD0! within 87 ms (+0.40) of the service request, or a break first")
    line = line_of(recorder, case, "service-request", "two-sensors", "families")
    case.extend(
        f for f in judge_break_rules(line, recorder.uncertainty) if f.requirement == "R-7.1-01"
    )
