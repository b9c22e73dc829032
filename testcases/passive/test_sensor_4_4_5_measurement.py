"""Sensor rules, sections 4.4.5-4.4.7: measurement replies, service requests and concurrent
replies, as far as the recorded measurements show them."""

from __future__ import annotations

import pytest

from conformance.judges import measurements as judge
from conformance.protocol.commands import Kind

from ._helpers import judged

requirements = pytest.mark.requirements


@requirements("R-4.4.5-01", "R-4.4.5-02")
@pytest.mark.preconditions("heard")
def test_measurement_reply(heard_sensors, case):
    """Every recorded aM!/aMn!/aMC!/aV! is answered 'atttn' (n >= 1 for a defined group)."""
    case.expect("'atttn<CR><LF>' to each recorded aM!-type command")
    ms = heard_sensors.of_kind(Kind.MEASURE, Kind.VERIFY)
    case.evidence("recorded M-family replies", [m.start for m in ms])
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))


@requirements("R-4.4.6-01", "R-4.4.6-02", "R-4.4.6-04", "R-4.4.5-08", "R-4.4.5-09")
@pytest.mark.preconditions("heard")
def test_service_request(heard_sensors, case):
    """After 'atttn' with ttt > 0 the sensor sends 'a<CR><LF>' within ttt, nothing else."""
    case.expect("exactly 'a<CR><LF>' within ttt of the reply; ttt not much longer than needed")
    ms = [m for m in heard_sensors.of_kind(Kind.MEASURE, Kind.VERIFY, whole=True) if m.ttt]
    case.evidence("recorded measurements with ttt > 0", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))


@requirements("R-4.4.7-01", "R-4.4.7-02", "R-4.4.7-03")
@pytest.mark.preconditions("heard")
def test_concurrent_reply(heard_sensors, case):
    """Every recorded aC!/aCn!/aCC! is answered 'atttnn'."""
    case.expect("'atttnn<CR><LF>' to each recorded aC!-type command")
    ms = heard_sensors.of_kind(Kind.CONCURRENT)
    case.evidence("recorded C-family replies", [m.start for m in ms])
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))
