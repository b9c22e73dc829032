"""Section 7.2: retries after no reply, an invalid reply, a bad CRC or a pause in the reply."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.retries import judge_breaks_over_replies, judge_retries

from ._helpers import line_of

requirements = pytest.mark.requirements
RETRY_SCENARIOS = (
    "silent-twice",
    "silent-six",
    "bad-crc-once",
    "parity-once",
    "parity-mid-reply",
    "pause-once",
    "format-once",
    "reply-at-window-edge",
)


@requirements("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-04", "R-7.2-05", "R-7.2-06")
@pytest.mark.preconditions("recorder")
def test_retries(recorder, case):
    """Silent, garbled, paused and bad-CRC replies are retried inside the section 7.2 windows,
    in up to three break+command+retries sequences."""
    case.expect(
        "retry 16.67-87 ms after an unanswered command, two retries per sequence with one "
        "more than 100 ms after the break, three sequences before giving up (SHOULD), a retry "
        "for every invalid reply, only after that reply ended"
    )
    line = line_of(recorder, case, *RETRY_SCENARIOS)
    case.extend(judge_retries(line, recorder.uncertainty))
    # a break over a reply still coming and the command again is no retry that waited for
    # the response to complete, in any scenario: the long replies are in the others (a 40-
    # character buffer broke into aHA!'s and aC9!'s 75-character D replies unjudged)
    others = [n for n in recorder.applicable() if n not in RETRY_SCENARIOS]
    if line is not None and others:
        rest = line_of(recorder, case, *others, whole_run=True)
        if rest is not None:
            case.extend(judge_breaks_over_replies(rest, recorder.uncertainty))
