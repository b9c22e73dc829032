"""The wait rules over the measurements other cases made again (truth31,
conformance.judges.other_waits): a deviation there FAILs (or WARNs) beside the owners'
findings, under the same preconditions; what they cannot decide never outweighs an owner.

The sessions are the simulated sensor; the hand-typed records are those of the host-stall
tests (tests/judges/test_waits_host_stall.py)."""

from __future__ import annotations

from conformance.case import Case
from conformance.judges import measurements as judge
from conformance.judges.other_waits import QUIET_IDS, WAIT_IDS, judge_other_waits
from conformance.links.host_stall import Stall
from conformance.ports import open_sim, parse_sim
from conformance.preconditions import declared_on
from conformance.results import CaseRecord, counted, partial_only
from conformance.sensor.session import SensorSession
from conformance.transcript import TOOL, Event, EventKind, decode_7e1
from conformance.verdicts import Finding, Verdict, passed, worst
from testcases.sensor.test_9_whole_run import (
    test_service_requests_of_every_measurement as every_wait_case,
)
from tests.judges.test_waits_host_stall import Run, U, _late_request
from tests.support.hand_events import chars

LATE_AGAIN = "late-service-request-when-repeated"


def _session(faults: str = "") -> SensorSession:
    opened = open_sim(parse_sim(f"sim://?faults={faults}" if faults else "sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def _case(session: SensorSession) -> dict[str, Finding]:
    """The whole-run case's findings over ``session``'s measurements made again."""
    record = CaseRecord("every-wait", "every-wait", WAIT_IDS)
    every_wait_case(session, Case(record, preconditions=declared_on(every_wait_case, WAIT_IDS)))
    return {f.requirement: f for f in record.findings}


def _rule(findings: list[Finding]) -> Verdict:
    """The rule's verdict as the run aggregates its findings."""
    kept = counted(findings)
    short = partial_only("R", kept)
    return worst(f.verdict for f in ([short] if short else []) + kept)


def test_a_request_late_only_when_measured_again_fails_the_rule():
    """The cached aM! (the owner's) is in time; the case's second aM! is late: FAIL, where
    base-s68 judged only the first and PASSed."""
    session = _session(LATE_AGAIN)
    owned = session.measurement("M")
    session.fresh_measurement("M")
    (own,) = judge.judge([owned], ["R-4.4.6-04"], session.version)
    assert own.verdict is Verdict.PASS, own.detail
    found = _case(session)["R-4.4.6-04"]
    assert found.verdict is Verdict.FAIL, found.detail
    assert "made again" in found.detail and "past ttt=" in found.detail
    assert _rule([own, found]) is Verdict.FAIL
    assert {f.verdict for f in _case(session).values()} - {Verdict.FAIL} <= {
        Verdict.PASS,
        Verdict.NA,
    }


def test_the_clean_sensor_measured_again_passes_in_part():
    session = _session()
    session.measurement("M")
    session.fresh_measurement("M")
    found = _case(session)
    assert found["R-4.4.6-04"].verdict is Verdict.PASS
    assert found["R-4.4.6-04"].partial  # it speaks for these measurements, not the rule
    # no concurrent measurement made again: N/A, which leaves their own cases' verdicts
    assert {found[rid].verdict for rid in QUIET_IDS} == {Verdict.NA}
    assert [m.command.text() for m in session.remeasured] == ["0M!"]


def test_a_partial_pass_alone_does_not_pass_the_rule():
    """Where no owner judged the rule (a partial run), these measurements' PASS is not the
    rule's."""
    session = _session()
    session.fresh_measurement("M")
    found = _case(session)["R-4.4.6-04"]
    assert _rule([found]) is Verdict.INCONCLUSIVE


def test_no_measurement_made_again_is_no_verdict():
    (none,) = judge_other_waits([], ["R-4.4.6-04"], "14")
    assert none.verdict is Verdict.NA
    owner = passed("R-4.4.6-04", "conforms", observed=5)
    assert _rule([owner, none]) is Verdict.PASS


def test_a_partial_run_that_measured_nothing_again_measures_once_itself():
    """-k test_9_whole_run or --req: no case measured again, so the case makes one aM! of its
    own and judges it as a full run's case judges the others' (CI: alone it was N/A, PASS
    in the full run); the concurrent quiet stays N/A (no concurrent one made)."""
    session = _session()
    session.measurement("M")  # cached: the owner's, not this case's
    assert not session.remeasured
    found = _case(session)
    assert [m.command.text() for m in session.remeasured] == ["0M!"]
    assert {found[rid].verdict for rid in QUIET_IDS} == {Verdict.NA}
    assert {f.verdict for r, f in found.items() if r not in QUIET_IDS} == {Verdict.PASS}
    assert all(f.partial for r, f in found.items() if r not in QUIET_IDS)
    owner = passed("R-4.4.6-04", "conforms", observed=5)
    assert _rule([owner, found["R-4.4.6-04"]]) is Verdict.PASS
    late = _session("late-service-request")  # a late request in its own aM! FAILs
    assert _case(late)["R-4.4.6-04"].verdict is Verdict.FAIL


def test_a_late_request_across_a_stall_leaves_the_owner_s_pass():
    """The stall over the request's stamp: undecided, observed 0, so the owner's PASS
    stands; the same request outside any stall FAILs."""
    (held,) = judge_other_waits(_late_request(True).measurements, ["R-4.4.6-04"], "14")
    assert held.verdict is Verdict.INCONCLUSIVE and held.observed == 0, held.detail
    assert "stalled" in held.detail
    owner = passed("R-4.4.6-04", "conforms", observed=5)
    assert _rule([owner, held]) is Verdict.PASS
    (late,) = judge_other_waits(_late_request(False).measurements, ["R-4.4.6-04"], "14")
    assert late.verdict is Verdict.FAIL
    assert _rule([owner, late]) is Verdict.FAIL


def test_no_atttn_reply_is_no_wait_to_judge():
    """A start the sensor did not answer (it may not have heard it): no request owed."""
    run = Run()
    run.events.append(Event(EventKind.BREAK, TOOL, 0.0, 0.0125, uncertainty=U))
    run.events += chars(TOOL, "0M!", 0.0215, uncertainty=U)
    run.t = 2.0
    run.exchange("0D0!", "0+1+2\r\n")
    ms = run.recorded(noted=False).measurements
    assert ms and not ms[0].start.answered
    found = judge_other_waits(ms, ["R-4.4.6-02", "R-4.4.6-04"], "14")
    assert {f.verdict for f in found} <= {Verdict.NA}, [f.detail for f in found]


def test_a_should_rule_warns_never_fails():
    """R-4.4.5-09 (SHOULD): a request 0.1 s after a reply announcing 9 s is a WARN."""
    run = Run()
    reply_end = run.exchange("0M!", "00092\r\n")
    run.sensor("0\r\n", reply_end + 0.1)
    run.exchange("0D0!", "0+1+2\r\n")
    ms = run.recorded(noted=False).measurements
    (found,) = judge_other_waits(ms, ["R-4.4.5-09"], "14")
    assert found.verdict is Verdict.WARN, found.detail


def test_a_service_request_after_a_concurrent_measurement_made_again_fails():
    """aC! measured again on a sensor that requests service after concurrent measurements:
    R-4.4.6-05 and R-4.4.7-04 FAIL; the clean sensor's PASS in part; the service-request
    rules, with no M-type measurement made again, N/A."""
    for faults, verdict in (("concurrent-service-request", Verdict.FAIL), ("", Verdict.PASS)):
        session = _session(faults)
        session.fresh_measurement("C")
        found = _case(session)
        assert {found[rid].verdict for rid in QUIET_IDS} == {verdict}, found
        assert {f.verdict for r, f in found.items() if r not in QUIET_IDS} == {Verdict.NA}


def test_the_abort_case_s_measurement_is_kept_with_its_wait_marked(monkeypatch):
    """``measure_as_sent`` (test_break_aborts_measurement's aM! right after its break) keeps
    the engine's record, its wait marked from the link's stall notes as a fresh
    measurement's is: a request late across a stall there is undecided, never a FAIL."""
    session = _session(LATE_AGAIN)
    session.measurement("M")
    first, began = len(session.link.transcript.events), session.link.now()
    asked: list[int] = []

    def stalls(since: int) -> list[Stall]:
        """A stall over the whole measurement, noted for the wait's marking alone (the
        engine's own reads, marked as they are made, read the notes since their own
        exchange: none there)."""
        asked.append(since)
        return [Stall(began, session.link.now(), 150.0)] if since == first else []

    monkeypatch.setattr(session.master, "stalls_since", stalls)
    m = session.measure_as_sent(session.command("M"))
    assert session.remeasured == [m] and first in asked
    assert m.wait_stall is not None
    found = _case(session)["R-4.4.6-04"]
    assert found.verdict is Verdict.INCONCLUSIVE and found.observed == 0, found.detail
    assert "stalled" in found.detail
    monkeypatch.undo()
    session.remeasured.clear()
    session.measure_as_sent(session.command("M"))  # no stall noted: the late request FAILs
    assert _case(session)["R-4.4.6-04"].verdict is Verdict.FAIL


def _disturbed(faults: str, own: bool) -> SensorSession:
    """``faults``' session after aC! disturbed by aI! to itself (``own``) or to another
    address, as the concurrent cases disturb it."""
    session = _session(faults)
    poke = f"{session.address if own else session.foreign_address()}I!"
    session.disturbed_measurement(session.command("C"), poke)
    return session


def test_a_request_after_a_disturbed_concurrent_measurement_fails():
    """truth35: the wait of a concurrent measurement disturbed by a command to another
    address, past the poke's reply window, is judged too: concurrent-service-request's
    request there FAILs R-4.4.6-05 and R-4.4.7-04; the clean sensor's quiet PASSes in part.
    aI! to the sensor itself aborts the measurement: nothing of it is kept (after that abort
    abort-sends-zero-reply's unasked 'a0000<CR><LF>' is the abort rules' to judge)."""
    bad = _disturbed("concurrent-service-request", False)
    (m,) = bad.disturbed
    assert decode_7e1(m.waited_events) == "0\r\n"
    found = _case(bad)
    assert {found[rid].verdict for rid in QUIET_IDS} == {Verdict.FAIL}, found
    clean = _disturbed("", False)
    (m,) = clean.disturbed
    assert m.waited_events == [] and m.data
    found = _case(clean)
    assert {found[rid].verdict for rid in QUIET_IDS} == {Verdict.PASS}, found
    assert all(found[rid].partial for rid in QUIET_IDS)
    for faults in ("", "abort-sends-zero-reply", "concurrent-service-request"):
        assert _disturbed(faults, True).disturbed == []


def test_a_disturbance_whose_reply_window_covers_ttt_leaves_the_wait_unjudged(monkeypatch):
    """Where the poke's reply window (LATE_START_LISTEN past it) reaches the time the
    measurement is ready, what came there may be the poke's: the measurement is not kept."""
    monkeypatch.setattr("conformance.sensor.session.LATE_START_LISTEN", 60.0)
    session = _disturbed("concurrent-service-request", False)
    assert session.disturbed == []
    found = _case(session)
    assert {found[rid].verdict for rid in QUIET_IDS} == {Verdict.NA}
