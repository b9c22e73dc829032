"""Section 4.4.8: the send-data command aD0..aD9!, value format, limits and grouping."""

from __future__ import annotations

import pytest

from conformance.judges import measurements as judge
from conformance.sensor_session import C_FAMILY, M_FAMILY

requirements = pytest.mark.requirements
ASCII_FAMILIES = M_FAMILY + C_FAMILY


@requirements("R-4.4.8-01", "R-4.4.8-02", "R-4.4-05")
def test_data_replies(sensor, case):
    """D replies are address + values [+ CRC] + CR LF; values are well formed; the values
    part stays within 35 characters after M-type commands and 75 after C-type ones."""
    case.expect(
        "'a<values>[<CRC>]<CR><LF>'; each value sign + 1..7 digits + at most one '.', "
        "at most 9 characters (decision A13 warns on odd spellings)"
    )
    ms = sensor.defined(ASCII_FAMILIES)
    case.evidence("every defined measurement's D replies", ms)
    case.extend(judge.judge(ms, case.requirements, sensor.version))


@requirements("R-4.4.8-03", "R-4.4.8-04")
def test_announced_values_delivered(sensor, case):
    """The D replies add up to the announced count; D0 is not empty when values are due."""
    case.expect("D0, D1, ... return exactly n (or nn, nnn after aHA!) values in all")
    ms = sensor.defined(ASCII_FAMILIES + ("HA",))
    case.evidence("every defined measurement", ms)
    case.extend(judge.judge(ms, case.requirements, sensor.version))


@requirements("R-4.4.8.3-01", "R-4.4.8.3-02", "R-4.4.8.3-03")
def test_value_grouping(sensor, case):
    """No value split over two replies; groups in order from D0; replies filled (SHOULD)."""
    case.expect(
        "every D reply starts with a sign; no empty Dk before a Dk+1 with values; a "
        "reply leaves no room for the next reply's first value"
    )
    ms = sensor.defined(ASCII_FAMILIES)
    case.evidence("every defined measurement", ms)
    case.extend(judge.judge(ms, case.requirements, sensor.version))
