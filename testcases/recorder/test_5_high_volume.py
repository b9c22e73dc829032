"""Section 5: high-volume ASCII past D9 and high-volume binary packets (v1.4 recorders)."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.collection import judge_high_volume
from conformance.judges.recorder.measurements import observed_measurements

from ._helpers import line_of

requirements = pytest.mark.requirements


@requirements("R-5.1-04", "R-5.2-08", "R-5.4-01")
@pytest.mark.preconditions("recorder")
def test_high_volume(recorder, case):
    """aHA! data are read through D14 without leading zeros; aHB! packets are read in 8N1
    until every value (or the empty packet) is in; a v1.4 recorder supports both."""
    case.expect("0D10!..0D14! (never 0D010!); DB0..DB9 read, CRC checked, then stop")
    line = line_of(recorder, case, "high-volume-ascii", "high-volume-binary")
    if line is None:
        return
    taken = observed_measurements(line, recorder.uncertainty)
    sent = {s.text for s in line.transmissions}
    cut = bool(line.cut_parts)
    case.extend(judge_high_volume(taken, recorder.is_v14, sent, cut, line.stalls))
