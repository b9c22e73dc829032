"""R-6.1-03's listening after the identify commands (issue 22, sixth round).

The case listens for a service request a sensor would owe had it taken ``aIM!`` for ``aM!``
(``aIV!`` for ``aV!``): before that measurement's ttt has passed since the identify reply
(R-4.4.6-04), with the engine's late-service-request grace past it. It used to count the
longest ttt from the last identify command (``aIV!``, some 0.36 s after ``aIM!``); each
window now runs from its own command's exchange, and the listening ends with the latest.
These tests hold the window: a service request after ``aIM!`` alone, at once or just before
its ttt runs out (the latest a conforming one comes), is heard and FAILs the rule; on the
clean sensor the listening ends where ``aIM!``'s window does."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.case import Case
from conformance.ports import open_sim, parse_sim
from conformance.preconditions import declared_on
from conformance.results import CaseRecord
from conformance.sensor.session import SensorSession
from conformance.transcript import TOOL, EventKind, decode_7e1
from conformance.verdicts import Verdict
from testcases.sensor.test_6_metadata import test_identify_starts_nothing as identify_case

RULE = ("R-6.1-03",)


def _session(sr_after_im: float | None = None) -> SensorSession:
    """The reference sensor; with ``sr_after_im``, one that takes ``aIM!`` for ``aM!`` and
    sends its service request that long after the identify reply (``aIV!`` announces ttt 0
    and starts nothing, so only ``aIM!``'s window can hear it)."""
    opened = open_sim(parse_sim("sim"))
    if sr_after_im is not None:
        emulator = opened.devices[0]
        specs = dict(emulator.profile.measurements)
        specs["M"] = replace(specs["M"], ready_after=sr_after_im)
        specs["V"] = replace(specs["V"], ttt=0, ready_after=None)
        emulator.profile = replace(emulator.profile, measurements=specs)
        emulator.behaviour = replace(emulator.behaviour, service_request_on_identify=True)
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def _judged(session: SensorSession) -> list[Verdict]:
    record = CaseRecord("identify", "identify", RULE)
    identify_case(session, Case(record, preconditions=declared_on(identify_case, RULE)))
    return [f.verdict for f in record.findings]


def _tool_commands(session: SensorSession) -> list[tuple[str, float, float]]:
    """(text, start of its first character, end of the exchange's last event) per command."""
    events = [e for e in session.link.transcript.events if e.kind is not EventKind.NOTE]
    out: list[tuple[str, float, float]] = []
    current: list = []
    for e in events:
        if e.kind is EventKind.CHAR and e.origin == TOOL:
            current.append(e)
            if e.char7 == ord("!"):
                out.append((decode_7e1(current), current[0].start, e.end))
                current = []
        elif out and e.kind is EventKind.CHAR:
            text, start, _ = out[-1]
            out[-1] = (text, start, e.end)  # the reply's end
    return out


def test_the_clean_sensor_passes_and_the_listening_ends_with_aim_s_window():
    session = _session()
    assert _judged(session) == [Verdict.PASS]
    commands = _tool_commands(session)
    texts = [c[0] for c in commands]
    im = texts.index("0IM!")
    iv = texts.index("0IV!", im)
    assert texts[im : iv + 1] == ["0IM!", "0IC!", "0IHA!", "0IV!"]
    grace = session.master.policy.late_sr_grace
    m_ttt = session.measurement("M").ttt
    window_end = commands[im][2] + m_ttt + grace
    after = commands[iv + 1]  # the first read of the data again
    # the first re-read's break comes when the listening ended: at aIM!'s window's end
    breaks = [
        e.start
        for e in session.link.transcript.events
        if e.kind is EventKind.BREAK and commands[iv][2] < e.start < after[1]
    ]
    assert breaks and breaks[0] >= window_end
    assert breaks[0] < window_end + 0.05  # not aIV!'s end + that ttt + 0.2 s more (0.56 s)


@pytest.mark.parametrize("sr_after", [0.1, 1.99], ids=["at-once", "just-before-ttt"])
def test_a_service_request_after_aim_alone_is_heard(sr_after):
    session = _session(sr_after)
    assert _judged(session) == [Verdict.FAIL]
