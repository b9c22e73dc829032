"""Declared preconditions (issue 18, part 2): every case states what the wire must show
before it judges, the checks live in conformance/preconditions.py, and a precondition the
wire did not show makes the requirements it guards INCONCLUSIVE with the evidence."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

import testcases
from conformance import preconditions as pre
from conformance.case import Case
from conformance.catalog import for_role
from conformance.matrix import run_once
from conformance.results import CaseRecord
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict, failed, passed
from tests.test_judges import exchange

ABORT = ("R-4.4.5.1-01", "R-4.4.5.1-02", "R-4.4.5.1-03")


def _cases():
    """Every conformance case of the suite: (module, name, requirements, marker or None)."""
    found = []
    for info in pkgutil.walk_packages(testcases.__path__, "testcases."):
        module = importlib.import_module(info.name)
        for name, fn in inspect.getmembers(module, inspect.isfunction):
            if not name.startswith("test_") or fn.__module__ != module.__name__:
                continue
            marks = {m.name: m for m in getattr(fn, "pytestmark", [])}
            if "requirements" in marks:
                found.append((info.name, name, marks["requirements"].args, marks.get(pre.MARKER)))
    return found


def test_every_case_declares_preconditions_for_every_requirement_it_judges():
    """The catalog walk: a case that judges a requirement without declaring what the wire must
    show first fails here (one with genuinely none declares "none")."""
    cases = _cases()
    assert len(cases) > 60
    testable = {r.id for role in ("sensor", "recorder") for r in for_role(role)}
    problems = []
    for module, name, rids, marker in cases:
        where = f"{module}::{name}"
        assert set(rids) <= testable, where
        if marker is None:
            problems.append(f"{where}: no @pytest.mark.preconditions")
            continue
        try:
            declared = pre.declaration(marker.args, marker.kwargs, rids)
        except pre.PreconditionError as exc:
            problems.append(f"{where}: {exc}")
            continue
        bare = set(rids) - declared.covered()
        if bare:
            problems.append(f"{where}: {sorted(bare)} judged with no precondition declared")
    assert not problems, "\n".join(problems)


def test_the_walk_catches_a_case_without_a_declaration(monkeypatch):
    """The walk above can fail: drop one case's declaration and it names that case."""
    from testcases.sensor import test_4_4_basic as module

    fn = module.test_acknowledge_active
    kept = [m for m in fn.pytestmark if m.name != pre.MARKER]
    monkeypatch.setattr(fn, "pytestmark", kept)
    with pytest.raises(AssertionError, match="test_acknowledge_active: no @pytest.mark"):
        test_every_case_declares_preconditions_for_every_requirement_it_judges()


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        (("awake-ish",), {}, "unknown precondition"),
        ((), {"pending": ("R-9.9-01",)}, "does not judge"),
        (("none", "listening"), {}, "cannot stand beside"),
    ],
)
def test_a_bad_declaration_is_refused(args, kwargs, message):
    with pytest.raises(pre.PreconditionError, match=message):
        pre.declaration(args, kwargs, ("R-4.4.5.1-01",))


def _case(*args, **kwargs) -> Case:
    rids = ("R-4.4.5.1-01", "R-4.4.5.1-02")
    record = CaseRecord("t::c", "c", rids)
    return Case(record, preconditions=pre.declaration(args, kwargs, rids))


def test_an_unmet_precondition_voids_verdicts_before_and_after_it():
    case = _case(pending=("R-4.4.5.1-01",))
    case.add(passed("R-4.4.5.1-01", "silence after the break", observed=2))
    unmet = pre.Unmet("pending", "the service request came first", ("t=1.0 s: '0<CR><LF>'",))
    assert case.requires("pending", unmet) is False
    case.add(failed("R-4.4.5.1-01", "late", observed=1, evidence=["x"]))
    case.add(passed("R-4.4.5.1-02", "D0 empty", observed=1))  # not guarded: stands
    by = {(f.requirement, f.verdict) for f in case.record.findings}
    assert by == {("R-4.4.5.1-01", Verdict.INCONCLUSIVE), ("R-4.4.5.1-02", Verdict.PASS)}
    (f,) = [f for f in case.record.findings if f.requirement == "R-4.4.5.1-01"]
    assert f.detail == "precondition not met: pending: the service request came first"
    assert f.evidence == ["t=1.0 s: '0<CR><LF>'"]
    assert case.record.preconditions == {"pending": f.detail}


def test_a_met_precondition_changes_nothing_and_an_undeclared_one_is_a_case_bug():
    case = _case("pending")
    assert case.requires("pending", None) is True
    case.add(passed("R-4.4.5.1-01", "ok", observed=1))
    assert [f.verdict for f in case.record.findings] == [Verdict.PASS]
    case.requires("standby", None)
    assert {f.verdict for f in case.record.findings} == {Verdict.PASS, Verdict.ERROR}


def _char(origin: str, at: float) -> Event:
    return Event(EventKind.CHAR, origin, at, at + 8.33e-3, wire=ord("0"))


def test_pending_from_the_wire():
    start = exchange("0M!", "00023\r\n", 1.0)
    end = start.attempts[-1].reply_events[-1].end
    brk = Event(EventKind.BREAK, TOOL, end + 0.05, end + 0.063)
    assert pre.pending(start, 2, [], brk) is None
    assert pre.pending(start, 2, [_char(TOOL, end + 0.01)], brk) is None  # the tool's own
    early = pre.pending(start, 2, [_char(DUT, end + 0.02)], brk)
    assert early is not None and "finished before the break" in early.text
    late = Event(EventKind.BREAK, TOOL, end + 2.5, end + 2.513)
    assert "ttt (2 s) had already run out" in pre.pending(start, 2, [], late).text
    silent = exchange("0M!", "", 1.0)
    assert "never started" in pre.pending(silent, 2, [], brk).text


def _abort(port: str) -> dict[str, dict]:
    data = run_once(port, ("-k", "test_break_aborts_measurement"))
    (test,) = data["tests"]
    checked = test["preconditions"]  # verdicts.json says which held and why one did not
    assert set(checked) <= {"pending", "aborted"} and "pending" in checked, checked
    return {r["id"]: r for r in data["requirements"]}


@pytest.mark.parametrize(
    "port",
    [
        "sim://?profile=quick-ready",
        "sim://?profile=quick-ready&faults=break-does-not-abort-measure",
    ],
)
def test_abort_on_a_measurement_that_finished_first_is_inconclusive(port):
    """Before: R-4.4.5.1-01 PASS ("no service request after the break") and R-4.4.5.1-02 WARN
    on a sensor whose service request had come before the break: nothing was aborted."""
    v = _abort(port)
    for rid in ABORT:
        assert v[rid]["verdict"] == "INCONCLUSIVE", (rid, v[rid])
        f = v[rid]["findings"][0]
        assert f["detail"].startswith("precondition not met: pending: the sensor had finished")
        assert any("'0<CR><LF>'" in e for e in f["evidence"]), f["evidence"]


def test_abort_still_judged_where_the_measurement_was_pending():
    clean = _abort("sim://")
    assert [clean[r]["verdict"] for r in ABORT] == ["PASS"] * 3
    kept = _abort("sim://?faults=break-does-not-abort-measure")
    assert kept["R-4.4.5.1-01"]["verdict"] == "FAIL"
    for rid in ABORT[1:]:  # nothing was aborted: what follows an abort is not judged
        assert kept[rid]["verdict"] == "INCONCLUSIVE"
        assert "precondition not met: aborted" in kept[rid]["findings"][0]["detail"]
    deaf = _abort("sim://?faults=no-recovery-after-abort")
    assert deaf["R-4.4.5.1-03"]["verdict"] == "FAIL"
