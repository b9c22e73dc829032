"""Recorder rules over every recorded transmission (section 7 and the command rules of
section 4): breaks and the marking after them, when a break is due, command text, character
gaps inside commands, the recorder's bit rate."""

from __future__ import annotations

import pytest

from conformance.links.base import NO_BIT_TIMING
from conformance.offline.recorder_windows import recorder_findings
from conformance.verdicts import inconclusive

from ._helpers import judged, judged_only

requirements = pytest.mark.requirements


@requirements("R-7.0-02", "R-7.0-06")
@pytest.mark.preconditions("heard")
def test_breaks(heard_recorder, case):
    """Every recorded break lasts at least 12 ms and is followed by 8.33 ms of marking."""
    case.expect("break >= 12 ms (-0.40); marking before the command >= 8.33 ms (-0.40)")
    judged(case, recorder_findings(heard_recorder.link).breaks)


@requirements("R-7.0-17", "R-7.1-01")
@pytest.mark.preconditions("heard")
def test_break_when_due(heard_recorder, case):
    """A break before every command to a new sensor, after more than 87 ms of marking, and
    before an aD0! that comes more than 87 ms after a service request."""
    case.expect("commands without a break only to the same sensor within 87 ms (+0.40)")
    judged_only(case, recorder_findings(heard_recorder.link).break_rules, *case.requirements)


@requirements("R-4.2-01", "R-4.4-04", "R-4.3-01")
@pytest.mark.preconditions("heard")
def test_command_text(heard_recorder, case):
    """Recorded commands are printable, start with an address and end with their only '!'."""
    case.expect("printable ASCII; the address first; '!' last and nowhere else")
    judged(case, recorder_findings(heard_recorder.link).command_text)


@requirements("R-7.0-13", "R-7.0-01", "R-4.1-01")
@pytest.mark.preconditions("heard")
def test_character_timing(heard_recorder, case):
    """At most 1.66 ms between command characters, at 1200 baud."""
    case.expect("every gap inside a command <= 1.66 ms; characters one 8.33 ms frame apart")
    found = recorder_findings(heard_recorder.link)
    judged(case, found.character_gaps)
    if heard_recorder.link.info.bit_timing:
        judged(case, [found.command_bit_rate])
    else:
        case.add(inconclusive("R-4.1-01", NO_BIT_TIMING))
