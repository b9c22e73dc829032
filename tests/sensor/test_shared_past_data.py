"""The reads past the high-volume data ride on the shared ``aHB!`` measurement (issue 22):
R-5.2-06's case made an ``aHB!`` of its own only so that its ``aDBn!`` indices referred to
the latest measurement; read right after the one every case shares, they say the same and
the run has one ``aHB!`` (4.4 s of bus time on the reference sensor) less."""

from __future__ import annotations

from conformance.case import Case
from conformance.ports import open_sim, parse_sim
from conformance.preconditions import declared_on
from conformance.results import CaseRecord
from conformance.sensor.session import PAST_DATA_INDEX, SensorSession
from conformance.transcript import TOOL, EventKind, decode_7e1
from conformance.verdicts import Verdict
from testcases.sensor.test_5_high_volume import test_empty_packet_past_data as past_data_case


def _session(faults: str = "") -> SensorSession:
    opened = open_sim(parse_sim(f"sim://?faults={faults}" if faults else "sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def _commands(session: SensorSession) -> list[str]:
    """The tool's commands on the transcript, in order."""
    out, current = [], []
    for e in session.link.transcript.events:
        if e.kind is EventKind.CHAR and e.origin == TOOL:
            current.append(e)
            if e.char7 == ord("!"):
                out.append(decode_7e1(current))
                current = []
    return out


def test_the_reads_past_the_data_follow_the_shared_measurement_at_once():
    session = _session()
    m = session.measurement("HB")
    assert m.complete and m.data
    commands = _commands(session)
    past = [f"0DB{len(m.data)}!", f"0DB{PAST_DATA_INDEX}!"]
    assert commands[-2:] == past  # nothing between the last packet read and them
    assert commands[-3] == m.data[-1].text
    sent = len(session.link.transcript)
    exchanges = session.packets_past_data()
    assert [ex.text for ex in exchanges] == past
    assert len(session.link.transcript) == sent  # asked again: nothing more on the wire


def test_the_case_sends_no_measurement_of_its_own():
    session = _session()
    record = CaseRecord("past", "past", ("R-5.2-06",))
    past_data_case(session, Case(record, preconditions=declared_on(past_data_case, ("R-5.2-06",))))
    assert [f.verdict for f in record.findings] == [Verdict.PASS]
    assert _commands(session).count("0HB!") == 1


def test_a_sensor_without_the_empty_packet_still_fails():
    session = _session("binary-no-empty-packet")
    record = CaseRecord("past", "past", ("R-5.2-06",))
    past_data_case(session, Case(record, preconditions=declared_on(past_data_case, ("R-5.2-06",))))
    assert [f.verdict for f in record.findings] == [Verdict.FAIL]


def test_no_reads_past_the_data_where_hb_announced_no_values():
    session = _session("high-volume-unsupported-silent")
    session.measurement("HB")
    assert session.packets_past_data() == []
    assert not any(c.startswith("0DB") for c in _commands(session))
