"""Section 4.4.7: concurrent measurements across sensors, and how many values a recorder keeps."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.collection import judge_concurrent_storage
from conformance.judges.recorder.measurements import observed_measurements
from conformance.judges.recorder.waits import judge_concurrent_waits

from ._helpers import line_of

requirements = pytest.mark.requirements


@requirements("R-4.4.7-06", "R-4.4.7-08")
@pytest.mark.preconditions("recorder")
def test_concurrent_measurements(recorder, case):
    """Two sensors measure at once: each one's data are asked for only after its ttt, and the
    recorder uses aC! and collects every value."""
    case.expect("first data command to each sensor at least ttt after its 'atttnn' reply")
    names = ("concurrent-two", "concurrent-ttt-zero", "concurrent-99", "families")
    line = line_of(recorder, case, *names)
    if line is None:
        return
    asked = [c for n in names for c in recorder.run(n).asked]
    taken = observed_measurements(line, recorder.uncertainty)
    case.extend(judge_concurrent_waits(taken, recorder.uncertainty))
    sent = {s.text for s in line.transmissions}
    found = judge_concurrent_storage(taken, asked, sent, cut=bool(line.cut_parts))
    case.extend(f for f in found if f.requirement == "R-4.4.7-08")


@requirements("R-4.4.7-07")
@pytest.mark.preconditions("recorder")
def test_ninety_nine_values(recorder, case):
    """A concurrent measurement of 99 values: at least 20 stored (2000 text), ideally all."""
    case.expect("all 99 values read through D0..D9 (fewer than 20: FAIL; fewer than 99: WARN)")
    line = line_of(recorder, case, "concurrent-99")
    taken = observed_measurements(line, recorder.uncertainty)
    case.extend(f for f in judge_concurrent_storage(taken) if f.requirement == "R-4.4.7-07")
