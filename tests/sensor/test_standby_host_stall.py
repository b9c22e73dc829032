"""The standby probes (R-7.0-14, R-7.0-15) read the tool's own host stalls (truth30).

A stall from the reply (or break) a probe's marking counts from to the end of its read may
have moved the probe past the 100 ms (a reply stamped late by the burst that delivered it
makes the marking look shorter than the sensor saw it), or cut the read that shows the
answer: the probe is no evidence either way. Here the simulated sensor's run gets the link's
NOTE of a stall after chosen probes (the sim itself never stalls): a probe with one is sent
again; where every try met one the rule is INCONCLUSIVE naming the stall, never PASS or FAIL.
A probe outside any stall is judged exactly as before (the controls)."""

from __future__ import annotations

import pytest

from conformance.case import Case
from conformance.links import host_stall
from conformance.preconditions import declared_on
from conformance.results import CaseRecord
from conformance.verdicts import Verdict
from testcases.sensor.test_7_timing import test_standby_after_100ms as after_100ms
from testcases.sensor.test_7_timing import test_standby_after_foreign_command as after_foreign
from tests.support.case_verdicts import case_rules, case_verdict, sim_session

STALL = 0.15  # s: the pause the link measured
WHY = "the tool's host stalled 150 ms"


def _stalled(faults: str, stalls: int | None):
    """The sim's session whose first ``stalls`` standby probes (``a!`` with no break; None:
    every one) get the NOTE of a stall just after their read, as the link writes it when
    its reader resumes; returns the session and the list of the probes sent."""
    session = sim_session(faults)
    master, sent = session.master, []
    raw = master.raw

    def noted_raw(text, **kw):
        ex = raw(text, **kw)
        if text == f"{session.address}!" and kw.get("break_first") is False:
            sent.append(ex)
            if stalls is None or len(sent) <= stalls:
                now = session.link.now()
                session.link.transcript.note(now, host_stall.note_text(STALL))
        return ex

    master.raw = noted_raw  # type: ignore[method-assign]
    return session, sent


def _finding(session, case_fn, rule: str):
    rules = case_rules(case_fn)
    record = CaseRecord(case_fn.__name__, case_fn.__name__, rules)
    case_fn(session, Case(record, preconditions=declared_on(case_fn, rules)))
    return [f for f in record.findings if f.requirement == rule]


@pytest.mark.parametrize(
    ("case_fn", "rule", "faults"),
    [
        (after_100ms, "R-7.0-15", ""),
        (after_100ms, "R-7.0-15", "standby-after-108ms"),
        (after_foreign, "R-7.0-14", ""),
        (after_foreign, "R-7.0-14", "never-standby"),
    ],
)
def test_every_probe_stalled_is_no_evidence_either_way(case_fn, rule, faults):
    """Silence (PASS on the clean sensor) and an answer (FAIL on the faulty one) alike."""
    session, sent = _stalled(faults, None)
    findings = _finding(session, case_fn, rule)
    assert [f.verdict for f in findings] == [Verdict.INCONCLUSIVE], findings
    assert WHY in findings[0].detail
    assert len(sent) > 2  # sent again before it gave up


@pytest.mark.parametrize(
    ("case_fn", "rule", "faults", "verdict", "again"),
    [
        (after_100ms, "R-7.0-15", "", Verdict.PASS, 1),
        (after_100ms, "R-7.0-15", "standby-after-108ms", Verdict.FAIL, 1),
        # the probe and its control go again together
        (after_foreign, "R-7.0-14", "", Verdict.PASS, 2),
        (after_foreign, "R-7.0-14", "never-standby", Verdict.FAIL, 2),
    ],
)
def test_a_stalled_probe_is_sent_again_and_judged_as_ever(case_fn, rule, faults, verdict, again):
    """One stalled probe: sent again, and the verdict is the unstalled run's."""
    session, sent = _stalled(faults, 1)
    assert case_verdict(session, case_fn, rule) is verdict
    plain, unstalled = _stalled(faults, 0)
    assert case_verdict(plain, case_fn, rule) is verdict  # the control: no stall at all
    assert len(sent) == len(unstalled) + again


def test_a_stall_before_the_wake_up_changes_nothing():
    """A NOTE of a stall noted before the wake-up the probe's marking counts from: judged
    as ever, nothing sent again."""
    session, sent = _stalled("standby-after-108ms", 0)
    session.link.transcript.note(session.link.now(), host_stall.note_text(STALL))
    session.listen(0.3)
    assert case_verdict(session, after_100ms, "R-7.0-15") is Verdict.FAIL
    plain, unstalled = _stalled("standby-after-108ms", 0)
    case_verdict(plain, after_100ms, "R-7.0-15")
    assert len(sent) == len(unstalled)
