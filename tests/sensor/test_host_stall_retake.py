"""A stimulus the tool's own host stalled on, and that some try of was not accepted, is sent
again (SensorSession._retake, truth26): its read may have been cut by the stall and its
stamps moved by the host, and a clean sensor was FAILed on it (truth25: 6 FAIL + 1 WARN
behind an RFC 2217 port while the tool's process was paused 80-200 ms every 0.3-0.9 s).

The sim stands in for the wire; the stall is the link's note (conformance.links.host_stall)
put in the transcript while the first take went, and that take's record is made to read as
a real cut one does (its try ended IDLE)."""

from __future__ import annotations

from conformance.links.host_stall import note_text
from conformance.ports import open_sim, parse_sim
from conformance.sensor.session import RETAKES, SensorSession
from conformance.tool_recorder.records import IDLE


def _session() -> SensorSession:
    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def _stalling(
    session: SensorSession,
    takes: int,
    *,
    stall: float = 0.12,
    cut: bool = True,
    method: str = "transact",
):
    """Make the first ``takes`` calls of the session's engine's ``method`` (``transact``
    or ``measure``, whose own exchanges go through ``transact`` unstalled) stalled: a
    host-stall note among their events and (``cut``) the first try read IDLE; returns the list each call's record is appended to."""
    master = session.master
    made: list = []

    def wrap(real):
        def call(*args, **kw):
            record = real(*args, **kw)
            if len(made) < takes:
                link = session.link
                link.transcript.note(link.now(), note_text(stall))
                if cut:
                    start = getattr(record, "start", None)
                    exchange = record if start is None or not hasattr(start, "attempts") else start
                    exchange.attempts[0].reason = IDLE
            made.append(record)
            return record

        return call

    setattr(master, method, wrap(getattr(master, method)))
    return made


def test_an_exchange_cut_while_the_host_stalled_is_taken_again():
    session = _session()
    made = _stalling(session, takes=1)
    judged = session.fresh_exchange("I")
    assert len(made) == 2  # sent again once
    assert judged.ok and judged.attempts[0].ok
    assert session.host_retakes == 1
    assert any("the tool's host stalled (up to 120 ms)" in a for a in session.assumptions)


def test_a_measurement_cut_while_the_host_stalled_is_taken_again():
    session = _session()
    made = _stalling(session, takes=1, method="measure")
    m = session.fresh_measurement("M")
    assert len(made) == 2
    assert m.start.ok and m.complete


def test_without_a_stall_a_failed_try_stands():
    """The sensor's own bad reply is never sent again: only the host's stall is a reason."""
    session = _session()
    made = _stalling(session, takes=1, stall=0.0)
    session.fresh_exchange("I")
    assert len(made) == 1 and session.host_retakes == 0


def test_a_stall_over_accepted_tries_is_not_taken_again():
    session = _session()
    made = _stalling(session, takes=1, cut=False)
    session.fresh_exchange("I")
    assert len(made) == 1


def test_takes_again_at_most_retakes_times_and_never_an_address_change():
    session = _session()
    made = _stalling(session, takes=10)
    session.fresh_exchange("I")
    assert len(made) == RETAKES + 1
    made.clear()
    session.fresh_exchange("A0")  # to its own address: the sensor stays where it is
    assert len(made) == 1
