"""Sensor rules over every recorded reply (section 7 and the framing of section 4): response
start, inter-character gaps, bit rate, parity, printable characters, CR LF, the address; and
the identification reply (section 4.4.2) where the recording holds one.

The timing and framing judges are folds fed the recording a window at a time, their
findings made once per sensor (``conformance.offline.sensor_windows``, issue 22): each case
reads those of its sensor (``heard_sensors.records``)."""

from __future__ import annotations

import pytest

from conformance.judges.exchanges import identification
from conformance.links.base import NO_BIT_TIMING
from conformance.protocol.commands import Kind
from conformance.verdicts import inconclusive

from ._helpers import heard, judged

requirements = pytest.mark.requirements


@requirements("R-7.0-09", "R-7.0-10")
@pytest.mark.preconditions("heard")
def test_response_start_window(heard_sensors, case):
    """Every recorded reply starts 7.93 to 15.40 ms after the command's last stop bit."""
    case.expect("8.33 ms (-0.40) <= delay <= 15.0 ms (+0.40), for every recorded reply")
    judged(case, heard_sensors.records.response_start)


@requirements("R-7.0-12", "R-7.0-01")
@pytest.mark.preconditions("heard")
def test_character_gaps(heard_sensors, case):
    """No more than 1.66 ms of marking between the characters of a recorded reply."""
    case.expect("every inter-character gap of every recorded reply <= 1.66 ms")
    judged(case, heard_sensors.records.gaps)


@requirements("R-4.1-01", "R-4.1-02", "R-4.2-02", "R-4.2-03", "R-4.3-01")
@pytest.mark.preconditions("heard")
def test_reply_framing(heard_sensors, case):
    """Every recorded reply is 1200 baud 7E1 (but aDBn! packets), printable, ends in CR LF
    and starts with the address of the sensor that answers."""
    case.expect("even parity, printable characters, CR LF at the end, the address first")
    if heard_sensors.link.info.bit_timing:
        judged(case, [heard_sensors.records.bit_rate])
    else:
        case.add(inconclusive("R-4.1-01", NO_BIT_TIMING))
    judged(case, heard_sensors.records.framing)


@requirements("R-4.4.2-01", "R-4.4.2-02")
@pytest.mark.preconditions("heard")
def test_identification(heard_sensors, case):
    """A recorded aI! reply has the identification fields and a valid version."""
    case.expect("'allccccccccmmmmmmvvvxxx...<CR><LF>' to each recorded aI!")
    asked = [ex for ex in heard_sensors.exchanges_of(Kind.IDENTIFY) if ex.answered]
    if not heard(case, asked, "no answered aI!"):
        return
    case.evidence("recorded aI! exchanges", asked)
    for ex in asked:
        _, found = identification(ex, ex.command.address)
        judged(case, found)
