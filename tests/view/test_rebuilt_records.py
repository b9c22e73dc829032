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
