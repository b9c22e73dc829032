"""The listening for a service request after a break aborts a measurement (R-4.4.5.1-01) and
after a measurement announcing ttt = 000 (R-4.4.6-03) (issue 22, seventh round).

A measurement owes its service request before its ttt has passed since its reply (R-4.4.6-04),
and the engine waits ``late_sr_grace`` past that for a late one after any M or V. The two
cases' silence is evidence only while their listening covers that whole window, counted from
the measurement's reply: it used to run ``ttt + 0.5`` s from the aborting break (a break, a
read's end and a turnaround later) and 0.5 s from the end of the ``aM1!`` read. These tests
hold the window: on the clean sensor the listening ends where the window does; a sensor that
the break does not abort, with its service request at ttt or ``late_sr_grace`` past it, is
heard and FAILs the rule."""

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
from testcases.sensor.test_4_4_5_measurement import test_break_aborts_measurement as abort_case
from testcases.sensor.test_4_4_5_measurement import test_ttt_zero as ttt_zero_case

ABORT = ("R-4.4.5-08", "R-4.4.5.1-01", "R-4.4.5.1-02", "R-4.4.5.1-03")
ZERO = ("R-4.4.6-03", "R-4.4.5-03")


def _session(**behaviour: object) -> SensorSession:
    """The reference sensor, its behaviour changed by ``behaviour``."""
    opened = open_sim(parse_sim("sim"))
    if behaviour:
        emulator = opened.devices[0]
        emulator.behaviour = replace(emulator.behaviour, **behaviour)
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def _verdicts(session: SensorSession, case_fn, rules: tuple[str, ...]) -> dict[str, Verdict]:
    record = CaseRecord(case_fn.__name__, case_fn.__name__, rules)
    case_fn(session, Case(record, preconditions=declared_on(case_fn, rules)))
    return {f.requirement: f.verdict for f in record.findings}


def _replies(session: SensorSession, first: int) -> list[tuple[str, float, float]]:
    """(command text, end of its reply, start of the break before the next command) for each
    tool command since transcript index ``first``, in order."""
    events = [e for e in session.link.transcript.since(first) if e.kind is not EventKind.NOTE]
    out: list[list] = []
    current: list = []
    for e in events:
        if e.kind is EventKind.BREAK:
            if out and out[-1][2] is None:
                out[-1][2] = e.start
        elif e.origin == TOOL:
            current.append(e)
            if e.char7 == ord("!"):
                out.append([decode_7e1(current), e.end, None])
                current = []
        elif out:
            out[-1][1] = e.end  # the reply's (or a later character's) end
    return [tuple(x) for x in out]


def test_the_abort_listening_ends_with_the_measurement_s_window():
    session = _session()
    m = session.measurement("M")  # the case's target on the reference sensor (ttt 2 s)
    grace = session.master.policy.late_sr_grace
    first = len(session.link.transcript)
    assert _verdicts(session, abort_case, ABORT)["R-4.4.5.1-01"] is Verdict.PASS
    rows = _replies(session, first)
    texts = [r[0] for r in rows]
    start = texts.index("0M!", texts.index("0D0!"))  # the fill's D0 first, then the target
    text, reply_end, aborting_break = rows[start]
    # the next break after the aborting one is the D0's: it comes when the listening ended
    later = [
        e.start
        for e in session.link.transcript.since(first)
        if e.kind is EventKind.BREAK and e.start > aborting_break
    ]
    window_end = reply_end + m.ttt + grace
    assert later[0] >= window_end
    assert later[0] < window_end + 0.05  # not ttt + grace from the break's end (~0.08 s more)


@pytest.mark.parametrize("late", [0.0, 0.45], ids=["at-ttt", "within-the-grace"])
def test_a_service_request_the_break_did_not_stop_is_heard(late):
    """The break aborts nothing and the service request comes ``late`` s past ttt (0: as
    the reference sends it, just before ttt): the listening hears it, the rule FAILs."""
    settings = {"break_aborts_measure": False}
    if late:
        settings["service_request_late"] = late
    session = _session(**settings)
    assert _verdicts(session, abort_case, ABORT)["R-4.4.5.1-01"] is Verdict.FAIL


def test_the_ttt_zero_listening_runs_the_grace_from_the_reply():
    session = _session()
    grace = session.master.policy.late_sr_grace
    first = len(session.link.transcript)
    verdicts = _verdicts(session, ttt_zero_case, ZERO)
    assert verdicts["R-4.4.6-03"] is Verdict.PASS
    rows = _replies(session, first)
    zero = next(r for r in rows if r[0] in ("0M1!", "0M2!", "0M!", "0V!") and r[2] is not None)
    _, reply_end, next_break = zero
    assert reply_end + grace <= next_break < reply_end + grace + 0.05


def test_a_service_request_after_ttt_zero_is_heard():
    session = _session(service_request_on_ttt_zero=True)
    assert _verdicts(session, ttt_zero_case, ZERO)["R-4.4.6-03"] is Verdict.FAIL
