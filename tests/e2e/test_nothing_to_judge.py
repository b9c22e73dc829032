"""No PASS without evidence, and no FAIL for a rule that cannot fail a device (issue 10).

The two rules are enforced where a finding is built (:class:`conformance.verdicts.Finding`);
these tests prove them on the finding itself, over the whole catalog, and end to end on a
sensor and a recorder that do nothing at all: not a single PASS may come out of either.
"""

from __future__ import annotations

import pytest

import conformance.run as run_module
from conformance.catalog import catalog, strongest_verdict
from conformance.conduct import run_once
from conformance.emulator import default_profile
from conformance.matrices.recorder_matrix import run_recorder_suite
from conformance.ports import OpenedPort, SimSpec, sim_declaration
from conformance.results import CaseRecord, aggregate
from conformance.sensor.session import SensorSession
from conformance.sim.bus import SimBus, SimLink
from conformance.sim.line_monitor import LineMonitor
from conformance.verdicts import NOTHING_TO_JUDGE, Finding, Verdict, passed


def test_a_pass_over_nothing_is_inconclusive():
    f = Finding("R-4.4.1-01", Verdict.PASS, "all 0 replies conform")
    assert f.verdict is Verdict.INCONCLUSIVE
    assert f.detail.startswith(NOTHING_TO_JUDGE)
    assert passed("R-4.4.1-01", "1 reply conforms", observed=1).verdict is Verdict.PASS
    assert passed("R-4.4.1-01", "no reply", observed=0).verdict is Verdict.INCONCLUSIVE


@pytest.mark.parametrize("rid", sorted(catalog()))
def test_no_should_or_may_rule_can_fail(rid):
    """Over the whole catalog: a broken SHOULD/MAY rule is at most a WARN, on the finding and
    in the requirement's aggregated verdict; a MUST rule keeps its FAIL."""
    req = catalog()[rid]
    f = Finding(rid, Verdict.FAIL, "broken", observed=1, evidence=["0! -> '(silence)'"])
    record = CaseRecord("t::a", "a", (rid,), findings=[f])
    role = "recorder" if req.role == "recorder" else "sensor"
    verdict = {r.requirement.id: r.verdict for r in aggregate(role, [record])}[rid]
    if req.level in ("SHOULD", "MAY"):
        assert strongest_verdict(rid) == "WARN"
        assert f.verdict is Verdict.WARN
        assert verdict in (Verdict.WARN, Verdict.NA)  # N/A: untestable in this role
    else:
        assert strongest_verdict(rid) == "FAIL"
        assert f.verdict is Verdict.FAIL
        assert verdict in (Verdict.FAIL, Verdict.NA)


def _silent_bus(port: str, **_bench: str) -> OpenedPort:
    """The sim bus with nothing on it that ever transmits, declared like the emulator."""
    declared = sim_declaration(default_profile("14"), SimSpec())
    return OpenedPort(SimLink(SimBus([LineMonitor()])), [], declared)


@pytest.mark.slow
def test_do_nothing_sensor_gets_no_pass(monkeypatch):
    """Every sensor case runs against a mute line (discovery, which would stop the run, is
    skipped): whatever the cases send, nothing answers, and nothing may PASS."""
    monkeypatch.setattr(run_module, "open_port", _silent_bus)
    monkeypatch.setattr(SensorSession, "discover", lambda self: None)
    data = run_once("sim", version="1.4", address="0")
    passes = [r["id"] for r in data["requirements"] if r["verdict"] == "PASS"]
    assert passes == []
    assert data["summary"]["counts"]["ERROR"] == 0
    assert len(data["tests"]) >= 50  # the cases did run


def test_do_nothing_recorder_gets_no_pass():
    data = run_recorder_suite("sim://?recorder=tests.support.do_nothing:idle_recorder")
    passes = [r["id"] for r in data["requirements"] if r["verdict"] == "PASS"]
    assert passes == []
    assert data["summary"]["counts"]["ERROR"] == 0
    for rid in ("R-4.4.14-01", "R-7.0-17"):
        verdict = next(r for r in data["requirements"] if r["id"] == rid)["verdict"]
        assert verdict == "INCONCLUSIVE", rid


def test_a_case_that_could_not_reach_a_rule_does_not_outvote_one_that_judged_it():
    judged = CaseRecord(
        "t::crc", "crc", ("R-4.4.12-05",), findings=[passed("R-4.4.12-05", "17 ok", observed=17)]
    )
    stopped = CaseRecord(
        "t::explore",
        "explore",
        ("R-4.4.12-05",),
        findings=[Finding("R-4.4.12-05", Verdict.INCONCLUSIVE, "no step exercised it")],
    )
    verdicts = {r.requirement.id: r.verdict for r in aggregate("sensor", [judged, stopped])}
    assert verdicts["R-4.4.12-05"] is Verdict.PASS
    # an INCONCLUSIVE that rests on observations (uncertainty across a limit) still counts
    straddling = Finding("R-4.4.12-05", Verdict.INCONCLUSIVE, "straddles", observed=1)
    stopped.findings = [straddling]
    verdicts = {r.requirement.id: r.verdict for r in aggregate("sensor", [judged, stopped])}
    assert verdicts["R-4.4.12-05"] is Verdict.INCONCLUSIVE


@pytest.mark.slow
def test_a_break_that_aborts_nothing_is_not_a_pass_without_a_service_request_baseline():
    """Issue 10: a sensor without service requests whose break does not abort aM! must not
    PASS R-4.4.5.1-01 for the mere absence of a service request after the break."""
    data = run_once("sim://?faults=no-service-request,break-does-not-abort-measure")
    verdict = next(r for r in data["requirements"] if r["id"] == "R-4.4.5.1-01")["verdict"]
    assert verdict != "PASS"
