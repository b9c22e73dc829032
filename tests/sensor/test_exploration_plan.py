"""The exploration's planned run (issue 22, round 8): the steps hypothesis draws are drawn
once a process and sent as hypothesis sends them. It must send, record and judge exactly
what hypothesis driving the sending machine does, on every fault of the emulator: the
faults that break an invariant (where hypothesis replays the failing example once) as well
as the clean runs (that test, one a fault, is in test_exploration_plans.py since issue 22's
ci9 round, beside the stored plans' test, so that hypothesis's own run of each fault, their
common reference, is made once), a run after another in the same process (the plan held),
and a junk strategy a caller put in place."""

from __future__ import annotations

from conformance.ports import open_sim, parse_sim
from conformance.sensor import exploration
from conformance.sensor.session import SensorSession
from conformance.transcript import Event


def _run(port: str, *, planned: bool) -> tuple[object, ...]:
    """Everything an exploration leaves: its record, its exchanges and the wire."""
    opened = open_sim(parse_sim(port))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    first = len(session.link.transcript)
    run = exploration.explore(session, planned=planned)
    wire = [_event(e) for e in session.link.transcript.since(first)]
    exchanges = [(ex.text, ex.reply_text, ex.answered) for ex in run.exchanges]
    return (run.steps, run.log, run.failing_sequence, run.observations, run.broken, exchanges, wire)


def _event(e: Event) -> str:
    return repr(e)  # every field, stamps included


def test_a_held_plan_sends_what_a_fresh_one_does() -> None:
    exploration.forget_plans()
    fresh = _run("sim://?faults=answers-foreign-address", planned=True)
    assert _run("sim://?faults=answers-foreign-address", planned=True) == fresh
    assert _run("sim://?faults=answers-foreign-address", planned=False) == fresh


def test_a_callers_junk_strategy_gets_a_plan_of_its_own(monkeypatch) -> None:
    from hypothesis import strategies as st

    exploration.forget_plans()
    usual = _run("sim", planned=True)
    monkeypatch.setattr(exploration, "JUNK", st.sampled_from(["M", "XX"]))
    other = _run("sim", planned=True)
    assert other == _run("sim", planned=False)
    assert other[1] != usual[1]
