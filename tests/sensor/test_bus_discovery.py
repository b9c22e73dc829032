"""Finding the sensors of a shared bus: ``a!`` at each address, never ``?!``; two sensors at
one address found from their colliding replies, one garbling sensor not taken for two."""

from __future__ import annotations

import pytest

from conformance.options import UsageError, bus_addresses, check_address, is_bus
from conformance.ports import PortError, open_sim, parse_sim
from conformance.sensor.bus_discovery import ALL_ADDRESSES, discover_bus


def found(url: str, addresses=ALL_ADDRESSES, sweep: bool = True):
    return discover_bus(open_sim(parse_sim(url)).link, addresses, sweep=sweep)


def test_every_sensor_is_found_by_trying_each_address():
    bus = found("sim://?sensors=0,1,3")
    assert bus.addresses == ("0", "1", "3") and not bus.duplicates
    assert [s.identification[-8:] for s in bus.found] == ["SN0001\r\n", "SN0002\r\n", "SN0003\r\n"]
    sent = "".join(ex.text for ex in bus.exchanges)
    assert "?" not in sent and len(bus.exchanges) == len(ALL_ADDRESSES) + 2 * 3


def test_two_sensors_at_one_address_are_a_duplicate_not_a_sensor():
    bus = found("sim://?sensors=0,0,3")
    assert bus.addresses == ("3",)
    assert [a for a, _ in bus.duplicates] == ["0"]
    assert "two sensors answer at address '0'" in bus.duplicates[0][1]


def test_one_sensor_garbling_its_reply_is_found_not_called_two():
    bus = found("sim://?sensors=0,1:ack-trailing-space", "01", sweep=False)
    assert bus.addresses == ("0", "1") and not bus.duplicates


def test_a_named_address_nothing_answers_is_silent():
    bus = found("sim://?sensors=0,1", "015", sweep=False)
    assert bus.addresses == ("0", "1") and bus.silent == ["5"]


def test_sim_sensors_parse_with_their_own_faults():
    spec = parse_sim("sim://?sensors=0,1:wrong-crc+crc-missing,3&faults=ack-trailing-space")
    assert spec.sensors == (("0", ()), ("1", ("wrong-crc", "crc-missing")), ("3", ()))
    opened = open_sim(parse_sim("sim://?sensors=0,1:wrong-crc,3&faults=ack-trailing-space"))
    assert [e.faults.names for e in opened.devices] == [
        ("ack-trailing-space",), ("ack-trailing-space", "wrong-crc"), ("ack-trailing-space",)
    ]  # fmt: skip
    assert opened.declaration.factory_fresh is False


@pytest.mark.parametrize(
    "url",
    ["sim://?sensors=0", "sim://?sensors=0,,1", "sim://?sensors=0,1&address=2",
     "sim://?sensors=0,$", "sim://?sensors=0,1:no-such-fault"],
)  # fmt: skip
def test_bad_sim_sensors_are_refused(url):
    with pytest.raises(PortError):
        open_sim(parse_sim(url))


def test_bus_addresses():
    assert bus_addresses("0,1,3") == ("0", "1", "3") and bus_addresses("all") is None
    assert is_bus("0,1") and is_bus("all") and not is_bus("0") and not is_bus(None)
    for bad in ("0,0", "0,$", "0,,1"):
        with pytest.raises(UsageError):
            check_address(bad)
    check_address("0,1,z")
    with pytest.raises(UsageError):  # one pytest run judges one DUT
        check_address("0,1", "--sdi12-address")
