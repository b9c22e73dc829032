"""One sensor's records rebuilt alone (``rebuild_records(view, only=a)``, what a passive
judgement of a bus now gives each sensor's run, issue 22) equal that sensor's share of the
whole run's records: the same exchanges, attempts, measurements and data. The cases that a
wrong cut would get wrong: an aM! whose data another sensor's exchange ends (R-4.4.5-06),
concurrent measurements whose data come across other sensors' traffic (R-4.4.7-05), a
command to the same sensor ending one (R-4.4.7.1-01), and retries (R-7.2-01)."""

from __future__ import annotations

import pytest

from conformance import emulator
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder import ToolRecorder
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view.rebuilt_records import Rebuilt, rebuild_records, rebuilt_exchanges
from conformance.view.segments import TranscriptView, read_view
from tests.support.bus_of_sensors import (
    ADDRESSES,
    as_heard,
    bus_of_sensors,
    concurrent_round,
    measured_past_another,
)
from tests.support.records_alike import exchange_fields, measurement_fields


def _share(whole: Rebuilt, address: str) -> tuple[list, list]:
    return (
        [exchange_fields(x) for x in whole.exchanges if x.text[:1] == address],
        [measurement_fields(m) for m in whole.measurements if m.command.address == address],
    )


def _alone(view: TranscriptView, address: str) -> tuple[list, list]:
    mine = rebuild_records(view, only=address)
    return [exchange_fields(x) for x in mine.exchanges], [
        measurement_fields(m) for m in mine.measurements
    ]


def _each_sensor_alike(view: TranscriptView) -> Rebuilt:
    whole = rebuild_records(view)
    for address in "0123456789":
        assert _alone(view, address) == _share(whole, address), address
    return whole


def test_an_m_measurements_data_ended_by_another_sensor_stays_ended_alone():
    """0M!, then 1I! before its service request, then 0D0!: the whole run's records give
    0M! no data (the very next exchange was another sensor's); sensor 0's alone must not
    take the 0D0! that follows once 1I! is left out."""
    bus, recorder = bus_of_sensors("01")
    measured_past_another(recorder)
    view = read_view(as_heard(bus))
    whole = _each_sensor_alike(view)
    assert [(x.command.text(), len(x.data)) for x in whole.measurements] == [("0M!", 0)]
    assert [x.text for x in rebuild_records(view, only="0").exchanges][:2] == ["0M!", "0D0!"]


@pytest.mark.parametrize("meddle", [{}, {"0": "0I!"}, {"1": "3I!"}])
def test_concurrent_measurements_across_other_sensors_traffic(meddle):
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES:
        recorder.identify(a)
    concurrent_round(recorder, meddle=meddle)
    whole = _each_sensor_alike(read_view(as_heard(bus)))
    assert len(whole.measurements) == 3 and any(m.data for m in whole.measurements)


@pytest.mark.parametrize("faults", [(), ("missing-crlf",), ("wrong-crc",), ("parity-error",)])
def test_one_sensors_retries_and_measurements(faults):
    _, link, _ = emulator.sim_sensor(faults=faults)
    master = ToolRecorder(link)
    master.acknowledge()
    master.identify()
    for text in ("0M!", "0MC!", "0C!", "0HB!"):
        master.measure(cmds.parse_command(text))
    whole = _each_sensor_alike(read_view(link.transcript.events))
    assert whole.measurements and whole.exchanges


def _wire(exchanges: list[tuple[str, str]]) -> list[Event]:
    """A break, the command and the reply ('' for none) of each, 7E1, back to back."""
    events: list[Event] = []
    t = 0.05
    for command, reply in exchanges:
        events.append(Event(EventKind.BREAK, TOOL, t, t + 0.0125))
        t += 0.0125 + CHAR_TIME
        for origin, text in ((TOOL, command), (DUT, reply)):
            for c in text:
                events.append(
                    Event(EventKind.CHAR, origin, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c)))
                )
                t += CHAR_TIME
            t += 0.0095
        t += 0.2
    return events


def test_a_sensors_unanswered_command_again_after_anothers_is_a_newexchange_fields():
    """1I! unanswered, 0I! answered, 1I! again: the whole run's records make the second 1I!
    an exchange of its own (the one before it was sensor 0's), not a retry of the first;
    sensor 1's records alone must not join them because 0I! is left out."""
    wire = _wire([("1I!", ""), ("0I!", "014TESTCO  SENSOR001\r\n"), ("1I!", ""), ("1I!", "")])
    whole = _each_sensor_alike(read_view(wire))
    assert [(x.text, len(x.attempts)) for x in whole.exchanges] == [
        ("1I!", 1),
        ("0I!", 1),
        ("1I!", 2),
    ]


def test_the_exchanges_one_at_a_time_are_the_whole_runs():
    """rebuilt_exchanges gives each exchange once its retries are in: the same exchanges,
    attempts and all, as rebuild_records holds (a retry given before it was joined would
    be read short by sensors_on and the decode-quality notes)."""
    wire = _wire([("1I!", ""), ("1I!", ""), ("0I!", "014TESTCO  SENSOR001\r\n"), ("1I!", "")])
    for view in (read_view(wire), _concurrent_bus_view()):
        whole = rebuild_records(view).exchanges
        assert [exchange_fields(x) for x in rebuilt_exchanges(view)] == [
            exchange_fields(x) for x in whole
        ]
    seen = [len(x.attempts) for x in rebuilt_exchanges(read_view(wire))]
    assert seen == [2, 1, 1]


def _concurrent_bus_view() -> TranscriptView:
    bus, recorder = bus_of_sensors()
    concurrent_round(recorder, meddle={"0": "0I!"})
    return read_view(as_heard(bus))
