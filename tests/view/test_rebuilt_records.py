"""The tool recorder's records rebuilt from the view of its transcript equal the records it
wrote while driving the bus: the sensor rules can then judge a recording no tool drove."""

from __future__ import annotations

import pytest

from conformance import emulator
from conformance.protocol import commands as cmds
from conformance.tool_recorder import ToolRecorder
from conformance.tool_recorder.records import Attempt, Exchange, Measurement
from conformance.view.rebuilt_records import rebuild_records
from conformance.view.segments import read_view

FAULTS = [
    (),
    ("wrong-crc",),
    ("parity-error",),
    ("missing-crlf",),
    ("no-service-request",),
    ("late-service-request",),
    ("chatter-before-service-request",),
    ("response-too-late",),
    ("inter-char-gap",),
    ("binary-crc-wrong",),
    ("fewer-values-than-announced",),
    ("d0-empty",),
]


def _drive(master: ToolRecorder) -> list[Exchange | Measurement]:
    out: list[Exchange | Measurement] = [master.acknowledge(), master.identify()]
    for text in ("0M!", "0MC!", "0C!", "0V!", "0HA!", "0HB!"):
        out.append(master.measure(cmds.parse_command(text)))
    out += [master.transact("0R0!"), master.transact("0XSN!"), master.transact("0I!")]
    return out


def _exchanges(records: list[Exchange | Measurement]) -> list[Exchange]:
    flat: list[Exchange] = []
    for r in records:
        flat += [r.start, *r.data] if isinstance(r, Measurement) else [r]
    return flat


def _attempt(a: Attempt) -> tuple:
    # ``end`` (when the engine stopped listening) is no wire fact: not compared
    return (a.break_event, a.command_events, a.reply_events, a.reason, a.sequence, a.retry)


def _measurement(m: Measurement) -> tuple:
    return (
        m.command,
        m.ttt,
        m.count,
        m.reply_end,
        m.service_request_end,
        m.waited_events,
        [d.text for d in m.data],
        m.values,
        m.packets,
        m.binary_value_count,
    )


@pytest.mark.parametrize("faults", FAULTS, ids=lambda f: ",".join(f) or "clean")
def test_records_rebuilt_from_the_view_equal_the_masters(faults):
    _, link, _ = emulator.sim_sensor(faults=faults)
    written = _drive(ToolRecorder(link))
    rebuilt = rebuild_records(read_view(link.transcript.events))
    live = _exchanges(written)
    assert [(e.text, e.command, e.reply_text) for e in rebuilt.exchanges] == [
        (e.text, e.command, e.reply_text) for e in live
    ]
    for a, b in zip(live, rebuilt.exchanges, strict=True):
        assert [_attempt(x) for x in a.attempts] == [_attempt(x) for x in b.attempts], a.text
    measured = [r for r in written if isinstance(r, Measurement)]
    assert [_measurement(m) for m in rebuilt.measurements] == [_measurement(m) for m in measured]


def test_a_fault_that_forces_retries_is_rebuilt_with_its_sequences():
    _, link, _ = emulator.sim_sensor(faults=("missing-crlf",))
    written = _exchanges(_drive(ToolRecorder(link)))
    assert any(len(e.attempts) > 3 for e in written)  # retries and repeated sequences
    rebuilt = rebuild_records(read_view(link.transcript.events)).exchanges
    assert [[(a.sequence, a.retry) for a in e.attempts] for e in rebuilt] == [
        [(a.sequence, a.retry) for a in e.attempts] for e in written
    ]


def _session(faults: tuple[str, ...] = ()):
    from conformance.ports import open_sim, parse_sim
    from conformance.sensor.session import SensorSession

    query = f"?faults={','.join(faults)}" if faults else ""
    opened = open_sim(parse_sim(f"sim://{query}"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


@pytest.mark.parametrize("faults", [(), ("missing-crlf",), ("no-service-request",)])
def test_the_live_session_hands_the_cases_the_views_records(faults):
    """A live sensor run's cases judge the records the view rebuilds from the wire (the view
    a recording is judged by), and the view reads every stimulus as the tool recorder did."""
    session = _session(faults)
    first = len(session.link.transcript)
    ex = session.fresh_exchange("I")
    m = session.fresh_measurement("M")
    assert session.view_disagreements == 0
    wire = session.link.transcript.since(first)
    rebuilt = rebuild_records(read_view(wire), session.master.policy)
    assert [e.text for e in rebuilt.exchanges][0] == ex.text
    assert ex.reply_text == rebuilt.exchanges[0].reply_text
    assert m.values == rebuilt.measurements[0].values and m.ttt == rebuilt.measurements[0].ttt
    assert not any("the view read otherwise" in a for a in session.assumptions)


def test_a_record_the_view_reads_otherwise_is_said_not_hidden():
    session = _session()
    made = session.master.transact("0I!")
    assert session._as_seen(made, None) is made
    assert session.view_disagreements == 1
    assert any("the view read otherwise" in a for a in session.assumptions)


def test_a_concurrent_measurement_keeps_its_data_across_other_sensors_traffic():
    """Three sensors measure concurrently, interleaved (aC! to each, then the D commands of
    each): every measurement gets its own address's aD0!/aD1! and all its values, as the
    engine collected them, although other sensors were addressed between."""
    from tests.support.bus_of_sensors import ADDRESSES, as_heard, bus_of_sensors, concurrent_round

    bus, recorder = bus_of_sensors()
    for a in ADDRESSES:
        recorder.identify(a)
    written = concurrent_round(recorder)
    rebuilt = rebuild_records(read_view(as_heard(bus))).measurements
    assert [m.command.text() for m in rebuilt] == ["0C!", "1C!", "3C!"]
    for live, found in zip(written, rebuilt, strict=True):
        assert found.count == live.count == 20 and found.value_count == 20
        assert [d.text for d in found.data] == [d.text for d in live.data]
        assert all(d.text[0] == found.command.address for d in found.data)
        assert found.values == live.values


def test_a_command_to_the_same_sensor_ends_a_concurrent_measurements_data():
    """0I! between 0C! and 0D0! aborts sensor 0's measurement (R-4.4.7.1-01): its records
    take no data after it, while sensors 1 and 3 keep theirs."""
    from tests.support.bus_of_sensors import as_heard, bus_of_sensors, concurrent_round

    bus, recorder = bus_of_sensors()
    concurrent_round(recorder, meddle={"0": "0I!"})
    rebuilt = rebuild_records(read_view(as_heard(bus))).measurements
    assert [len(m.data) for m in rebuilt] == [0, 2, 2]


def test_an_m_measurement_still_takes_only_the_very_next_exchange_as_its_data():
    """After aM! the recorder talks to no one else (R-4.4.5-06): a command to another
    sensor before 0D0! ends 0M!'s data in the records, as before."""
    from tests.support.bus_of_sensors import as_heard, bus_of_sensors, measured_past_another

    bus, recorder = bus_of_sensors("01")
    m = measured_past_another(recorder)
    assert m.data and m.data[0].text == "0D0!"  # on the wire, for a rebuild to take wrongly
    rebuilt = rebuild_records(read_view(as_heard(bus))).measurements
    assert [(x.command.text(), len(x.data)) for x in rebuilt] == [("0M!", 0)]
