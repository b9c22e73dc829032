"""Declared preconditions (issue 18, part 2): every case states what the wire must show
before it judges, the checks live in conformance/preconditions.py, and a precondition the
wire did not show makes the requirements it guards INCONCLUSIVE with the evidence."""

from __future__ import annotations

import importlib
import inspect
import json
import pkgutil

import pytest

import testcases
from conformance import preconditions as pre
from conformance.case import Case
from conformance.catalog import for_role
from conformance.conduct import run_once
from conformance.results import CaseRecord
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict, failed, passed
from tests.judges.test_judges import exchange

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
    data = run_once(port, keyword="test_break_aborts_measurement")
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


# -- every declared code is checked at run time, through Case.requires ----------------------


def _declared_codes() -> dict[str, set[str]]:
    """``module::case`` -> the codes its marker declares ("none" left out: nothing to
    check)."""
    found: dict[str, set[str]] = {}
    for module, name, rids, marker in _cases():
        if marker is not None:
            codes = set(pre.declaration(marker.args, marker.kwargs, rids).guards) - {"none"}
            found[f"{module}::{name}"] = codes
    return found


def unchecked(tests: list[dict], declared: dict[str, set[str]]) -> list[str]:
    """Each case of a run (verdicts.json "tests") that declares a code its run never checked
    (Case.requires records every check, met or not, in the case's "preconditions")."""
    problems = []
    for t in tests:
        missing = declared.get(t["id"].split("[")[0], set()) - set(t["preconditions"])
        if missing:
            problems.append(f"{t['id']}: declares {sorted(missing)} but never checked them")
    return problems


def test_the_run_time_comparison_can_fail():
    declared = {"m::test_x": {"buffered", "supported"}}
    tests = [{"id": "m::test_x", "preconditions": {"supported": "met"}}]
    assert unchecked(tests, declared) == ["m::test_x: declares ['buffered'] but never checked them"]
    tests[0]["preconditions"]["buffered"] = "precondition not met: buffered: no values"
    assert unchecked(tests, declared) == []


#: Codes only a DUT sharing its line with other sensors has to check (a sensor alone is
#: alone): tests/e2e/test_live_bus.py checks them on a bus of three.
BUS_CODES = {"alone", "others"}


def test_every_declared_precondition_is_checked_when_the_sensor_suite_runs():
    """Before: supported, buffered and address were declarations only (17 sensor cases
    declared a code they never checked); now each is checked on the wire by the case."""
    data = run_once("sim://")
    assert len(data["tests"]) > 55
    alone = {case: codes - BUS_CODES for case, codes in _declared_codes().items()}
    assert unchecked(data["tests"], alone) == []


def test_every_declared_precondition_is_checked_when_the_recorder_suite_runs():
    from conformance.matrices.recorder_matrix import run_recorder_suite

    for extra in ({}, {"version": "1.3"}):
        data = run_recorder_suite("sim", **extra)
        assert len(data["tests"]) > 12
        assert unchecked(data["tests"], _declared_codes()) == []
        assert all("recorder" in t["preconditions"] for t in data["tests"])


def test_the_passive_suite_checks_heard(tmp_path):
    """Each passive case routes its judges' findings through ``heard``: a rule the recording
    does not hold is "precondition not met: heard: not seen in the recording", never PASS."""
    from tests.commands.test_passive import live, passive

    first = live(tmp_path, "sim", "sensor")
    lines = (first / "transcript.jsonl").read_text(encoding="utf-8").splitlines()
    cut = tmp_path / "short.jsonl"  # no aHB! and no multi-line text in it
    cut.write_text("\n".join(lines[:400]) + "\n", encoding="utf-8")
    passive(cut, "sensor", tmp_path / "passive")
    data = json.loads((tmp_path / "passive" / "verdicts.json").read_text(encoding="utf-8"))
    assert unchecked(data["tests"], _declared_codes()) == []
    checked = {t["id"].split("::")[-1]: t["preconditions"] for t in data["tests"]}
    assert checked["test_high_volume_binary"]["heard"].startswith("precondition not met")
    unseen = [
        f
        for r in data["requirements"]
        for f in r["findings"]
        if f["detail"].startswith("precondition not met: heard: not seen in the recording")
    ]
    assert unseen and all(f["verdict"] == "INCONCLUSIVE" for f in unseen)


# -- a case that judges silence requires the sensor shown listening -------------------------

#: What judges silence or sends a one-off probe whose silence is judged.
SILENCE_CALLS = ("silent(", "silent_while_listening(", "heard_probe(", "try_invalid_address(")
#: The codes that show the sensor listening when the silence went out: it answered an a!
#: sent the same way (listening), or the wake-up just before (awake). A passive run's
#: counterpart is heard.
LISTENING_CODES = {"listening", "awake", "heard"}


def silence_without_listening(cases) -> list[str]:
    problems = []
    for module, name, rids, marker in cases:
        fn = getattr(importlib.import_module(module), name)
        source = inspect.getsource(fn)
        if not any(call in source for call in SILENCE_CALLS):
            continue
        codes = set(pre.declaration(marker.args, marker.kwargs, rids).guards) if marker else set()
        if not codes & LISTENING_CODES:
            problems.append(f"{module}::{name} judges silence without {sorted(LISTENING_CODES)}")
    return problems


def test_every_case_that_judges_silence_requires_a_listening_sensor():
    cases = _cases()
    judging = [c for c in cases if any(s in inspect.getsource(getattr(
        importlib.import_module(c[0]), c[1])) for s in SILENCE_CALLS)]  # fmt: skip
    assert len(judging) >= 8
    assert silence_without_listening(cases) == []


def test_the_silence_walk_catches_a_case_without_it():
    """Before: test_short_spacing_is_not_a_break judged silence declaring "standby" only."""
    module = "testcases.sensor.test_7_timing"
    name = "test_short_spacing_is_not_a_break"
    marker = pytest.mark.preconditions("standby").mark
    (problem,) = silence_without_listening([(module, name, ("R-7.0-03",), marker)])
    assert name in problem


# -- emulator faults that remove a precondition -----------------------------------------------


@pytest.mark.parametrize("fault", ["late-address-after-break", "slow-wake"])
def test_a_sensor_slow_to_wake_leaves_the_hand_made_probes_undecided(fault):
    """Before: R-7.0-03 and R-AppB-01 PASSed on the silence of a sensor that never heard the
    probe (it needs more than 9 ms of marking after a break); their controls, sent the same
    way with a real break and in one piece, go unanswered too."""
    data = run_once(f"sim://?faults={fault}")
    v = {r["id"]: r for r in data["requirements"]}
    for rid in ("R-7.0-03", "R-AppB-01"):
        assert v[rid]["verdict"] == "INCONCLUSIVE", v[rid]
        (f,) = v[rid]["findings"]
        assert f["detail"].startswith("precondition not met: listening:"), f
        assert any("(silence)" in e for e in f["evidence"]), f
    tests = {t["id"].split("::")[-1]: t["preconditions"] for t in data["tests"]}
    assert tests["test_partial_command_dropped"]["listening"].startswith("precondition not met")


def test_no_values_leave_the_value_rules_undecided():
    """Before: with every D reply empty (d0-empty), the value format, length and grouping
    rules PASSed over no value at all; the reply's shape (R-4.4.8-01) is still judged."""
    data = run_once("sim://?faults=d0-empty")
    v = {r["id"]: r["verdict"] for r in data["requirements"]}
    for rid in ("R-4.4.8-02", "R-4.4-05", "R-4.4.8.3-01", "R-4.4.8.3-02", "R-4.4.8.3-03"):
        assert v[rid] == "INCONCLUSIVE", rid
    assert v["R-4.4.8-01"] == "PASS"


def test_an_absent_capability_is_not_applicable_and_partial_keeps_a_fail():
    rids = ("R-4.4.5.1-01", "R-4.4.5.1-02")
    case = Case(CaseRecord("t::c", "c", rids), preconditions=pre.declaration(
        ("supported", "recorder"), {}, rids))  # fmt: skip
    case.add(failed("R-4.4.5.1-01", "bad", observed=1, evidence=["x"]))
    case.add(passed("R-4.4.5.1-02", "ok", observed=1))
    assert not case.requires("recorder", pre.acted(["scenario s: cut short"]))
    by = sorted((f.requirement, f.verdict) for f in case.record.findings)
    assert by == [
        ("R-4.4.5.1-01", Verdict.FAIL),
        ("R-4.4.5.1-01", Verdict.INCONCLUSIVE),
        ("R-4.4.5.1-02", Verdict.INCONCLUSIVE),
    ]
    other = _case("supported")
    assert not other.requires("supported", pre.served(False, "no such feature"))
    assert {f.verdict for f in other.record.findings} == {Verdict.NA}
    with pytest.raises(ValueError, match="checked with a 'buffered' outcome"):
        other.requires("supported", pre.buffered(None))
