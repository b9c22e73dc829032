"""Sensor rules, sections 4.4.8, 4.4.12 and 5: data replies, value format and limits, counts
against announcements, CRCs and high-volume data, over every recorded measurement."""

from __future__ import annotations

import pytest

from conformance.judges import measurements as judge
from conformance.protocol.commands import Kind

from ._helpers import judged

requirements = pytest.mark.requirements
ASCII = (Kind.MEASURE, Kind.VERIFY, Kind.CONCURRENT)


@requirements("R-4.4.8-01", "R-4.4.8-02", "R-4.4-05")
@pytest.mark.preconditions("heard")
def test_data_replies(heard_sensors, case):
    """Recorded D replies are address + values [+ CRC] + CR LF, values well formed and within
    the 35/75-character limit."""
    case.expect("'a<values>[<CRC>]<CR><LF>'; sign + 1..7 digits + at most one '.'")
    ms = [m for m in heard_sensors.of_kind(*ASCII, whole=True) if m.count]
    case.evidence("recorded measurements with data", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))
    _unread(heard_sensors, case)


@requirements("R-4.4.8-03", "R-4.4.8-04")
@pytest.mark.preconditions("heard")
def test_announced_values_delivered(heard_sensors, case):
    """The recorded D replies add up to the announced count; D0 is not empty when due."""
    case.expect("D0, D1, ... return exactly the announced number of values")
    ms = [m for m in heard_sensors.of_kind(*ASCII, Kind.HIGH_VOLUME_ASCII, whole=True) if m.count]
    case.evidence("recorded measurements with data", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))
    _unread(heard_sensors, case, Kind.HIGH_VOLUME_ASCII)


@requirements("R-4.4.8.3-01", "R-4.4.8.3-02", "R-4.4.8.3-03")
@pytest.mark.preconditions("heard")
def test_value_grouping(heard_sensors, case):
    """No value split over two replies; groups in order from D0; replies filled (SHOULD)."""
    case.expect("every D reply starts with a sign; no empty Dk before a Dk+1 with values")
    ms = [m for m in heard_sensors.of_kind(*ASCII, whole=True) if m.count]
    case.evidence("recorded measurements with data", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))
    _unread(heard_sensors, case)


def _unread(heard_sensors, case, *kinds: Kind) -> None:
    """The rules left open by a recorded start reply with no readable count
    (:func:`conformance.judges.measurements.unread_data`): no D command read its values.
    Every recorded one, not only the ``whole`` ones: with no aD0! after it, the
    recording counts it as interrupted by the recorder."""
    heard = heard_sensors.of_kind(*ASCII, *kinds)
    judged(case, judge.unread_data(heard, case.requirements))


@requirements("R-4.4.12-02", "R-4.4.12-03", "R-4.4.12-05", "R-4.4.12-06")
@pytest.mark.preconditions("heard")
def test_crc(heard_sensors, case):
    """Data after a CRC measurement carry a correct CRC, encoded in 3 characters; data after
    a plain one carry none."""
    case.expect("3 CRC characters before CR LF exactly after aMC!/aCC!/aHA! and their match")
    ms = [m for m in heard_sensors.of_kind(*ASCII, Kind.HIGH_VOLUME_ASCII, whole=True) if m.count]
    case.evidence("recorded measurements with data", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))


@requirements("R-5.1-01", "R-5.1-02", "R-5.1-03")
@pytest.mark.preconditions("heard")
def test_high_volume_ascii(heard_sensors, case):
    """A recorded aHA! is answered 'atttnnn' and its data read past D9 as needed."""
    case.expect("'atttnnn<CR><LF>'; D replies of up to 75 characters with CRC")
    ms = heard_sensors.of_kind(Kind.HIGH_VOLUME_ASCII, whole=True)
    case.evidence("recorded aHA! measurements", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))


@requirements(
    "R-5.2-01", "R-5.2-02", "R-5.2-03", "R-5.2-04", "R-5.2-05", "R-5.2-07", "R-5.2.1-01",
    "R-4.1-03",
)  # fmt: skip
@pytest.mark.preconditions("heard")
def test_high_volume_binary(heard_sensors, case):
    """A recorded aHB! is answered 'atttnnn' and its DB packets are well formed and hold the
    announced number of values."""
    case.expect("packets: address, size, type, payload, CRC; the announced values in all")
    ms = heard_sensors.of_kind(Kind.HIGH_VOLUME_BINARY, whole=True)
    case.evidence("recorded aHB! measurements", ms)
    judged(case, judge.judge(ms, case.requirements, heard_sensors.version))
