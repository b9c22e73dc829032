"""Sections 4.4 and 5.4: what the recorder logged is what the sensors sent."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.logged import judge_logged_values
from conformance.recorder.scenarios import SCENARIOS
from conformance.recorder_jobs import Task

from ._helpers import line_of, log_reports

requirements = pytest.mark.requirements
#: Every scenario in which the recorder takes measurements and logs their values.
LOG_SCENARIOS = tuple(
    name for name, s in SCENARIOS.items() if s.request.task in (Task.MEASURE, Task.CONCURRENT)
)


@requirements("R-4.4-02", "R-5.4-01")
@pytest.mark.preconditions("recorder")
def test_logged_values_are_the_values_sent(recorder, case):
    """Per measurement, the values the recorder logged (its harness's log lines, its
    SDI12_LOG_FILE, or its program's output) are the values the sensor sent: as many, in the
    same order, each with its sign, digits and decimal point."""
    case.expect("every measurement's logged values equal, as numbers, the values on the wire")
    names = [n for n in LOG_SCENARIOS if recorder.applies(n)]
    line = line_of(recorder, case, *names)
    if line is None:
        return
    reports = log_reports(recorder, names)
    case.extend(
        judge_logged_values(line, reports, recorder.uncertainty, high_volume=recorder.is_v14)
    )
