"""Section 4.4.8: D0..Dn continuation, and issuing a measurement again after an empty reply."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.collection import judge_data_collection
from conformance.judges.recorder.measurements import observed_measurements

from ._helpers import line_of

requirements = pytest.mark.requirements


@requirements("R-4.4.8-05")
@pytest.mark.preconditions("recorder")
def test_data_continuation(recorder, case):
    """The recorder reads D0, D1, D2... until every announced value is in, and issues the
    measurement again when a D reply comes back valid but empty."""
    case.expect("D indices in order until the count is reached; after 'a<CR><LF>', aM! again")
    names = (
        "d0-to-d2",
        "empty-data",
        "reply-at-window-edge",
        "concurrent-ttt-zero",
        "concurrent-99",
        "families",
    )
    line = line_of(recorder, case, *names)
    taken = observed_measurements(line, recorder.uncertainty)
    case.extend(judge_data_collection(taken, line.stalls))
