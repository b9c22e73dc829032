"""Section 4.4.12: the recorder checks the CRC of every reply that carries one."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.retries import judge_crc_checked

from ._helpers import line_of, logged

requirements = pytest.mark.requirements


@requirements("R-4.4.12-07")
@pytest.mark.preconditions("recorder")
def test_crc_mismatch_is_retried(recorder, case):
    """A D0 reply whose CRC does not match its values is retried, and its values not logged."""
    case.expect("0D0! sent again after the reply with the wrong CRC; the true values logged")
    line = line_of(recorder, case, "bad-crc-once")
    run = recorder.run("bad-crc-once")
    truth = list(run.expected_values("0", "M"))
    case.extend(
        judge_crc_checked(line, recorder.uncertainty, logged(recorder, "bad-crc-once"), truth)
    )
