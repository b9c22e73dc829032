"""The exploration's stored plans (issue 22): a plan an earlier process drew is sent without
hypothesis, and must send, record and judge exactly what hypothesis driving the sending
machine does, on every fault of the emulator; its key must change with whatever the draws
read; a damaged file, a caller's junk strategy or a process that may not write bytecode
draws afresh; and a whole ``--port sim`` process with a stored plan loads no hypothesis."""

from __future__ import annotations

import functools
import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from conformance.emulator import FAULTS
from conformance.ports import open_sim, parse_sim
from conformance.sensor import exploration, exploration_plans, exploration_steps
from conformance.sensor.exploration_plans import PlanStore, as_plan, plan_key
from conformance.sensor.session import SensorSession

from .test_exploration_plan import _run

SENSOR_FAULTS = sorted(n for n, f in FAULTS.items() if not f.bus)


@pytest.fixture
def store(tmp_path, monkeypatch) -> PlanStore:
    """A store of its own, read (whatever an earlier test's ``forget_plans`` said)."""
    fresh = PlanStore(tmp_path / "plans")
    monkeypatch.setattr(exploration_plans, "STORE", fresh)
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    return fresh


def _session(port: str) -> SensorSession:
    opened = open_sim(parse_sim(port))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def _drawn(foreign: list[str], examples: int = 10, steps: int = 25):
    """The plan hypothesis draws, as a planned run draws it."""
    machine = exploration._machine_module()
    with exploration.no_local_constants(), exploration.no_database_key():
        return machine.plan_for(foreign, exploration.JUNK, examples, steps)


def _store_the_plan_of(port: str, store: PlanStore) -> str:
    foreign = exploration_steps.foreign_addresses(_session(port))
    key = plan_key(foreign, 10, 25)
    assert key is not None and store.store(key, _drawn(foreign))
    return key


def test_the_exceptions_are_hypothesis_s() -> None:
    """The stored plan's runner catches and lets through what hypothesis's does."""
    from hypothesis.core import failure_exceptions_to_catch, skip_exceptions_to_reraise

    assert exploration_steps.failure_exceptions() == failure_exceptions_to_catch()
    assert exploration_steps.skip_exceptions() == skip_exceptions_to_reraise()
    assert len(exploration_steps.skip_exceptions()) >= 1  # pytest's Skipped, in this process


@functools.cache
def hypothesis_s(port: str) -> tuple[object, ...]:
    """What hypothesis driving the sending machine sends, records and judges against
    ``port``: the reference of both tests below, made once a process (issue 22's ci9 round:
    each of the ~130 faults made it twice, once in each test, in two modules; a derandomised
    exploration is the same every time in a process, which
    :func:`test_hypothesis_s_run_is_the_same_made_again_beside_a_stored_plan` holds)."""
    return _run(port, planned=False)


def _port(fault: str) -> str:
    return f"sim://?faults={fault}" if fault else "sim"


@pytest.mark.parametrize("fault", ["", *SENSOR_FAULTS])
def test_planned_exploration_is_hypothesis_s_R_4_0_01_R_4_3_01(fault: str) -> None:
    """A plan drawn afresh in this process (round 8; in test_exploration_plan.py before)."""
    port = _port(fault)
    exploration.forget_plans()
    assert _run(port, planned=True) == hypothesis_s(port)


@pytest.mark.parametrize("fault", ["", "answers-foreign-address", "wrong-crc"])
def test_hypothesis_s_run_is_the_same_made_again_beside_a_stored_plan(
    fault: str, store: PlanStore
) -> None:
    """The kept reference is the one each test made for itself before: made again after a
    planned run and with a stored plan in place, it is equal."""
    port = _port(fault)
    kept = hypothesis_s(port)
    exploration.forget_plans()
    _run(port, planned=True)
    _store_the_plan_of(port, store)
    assert _run(port, planned=False) == kept


@pytest.mark.parametrize("fault", ["", *SENSOR_FAULTS])
def test_a_stored_plan_sends_what_hypothesis_sends_R_4_0_01_R_4_3_01(
    fault: str, store: PlanStore, monkeypatch
) -> None:
    port = _port(fault)
    _store_the_plan_of(port, store)
    hypothesis_s_ = hypothesis_s(port)
    machine = exploration._machine_module()
    monkeypatch.setattr(machine, "plan_for", lambda *a: pytest.fail("drew a stored plan"))
    monkeypatch.setattr(machine, "machine_class", lambda *a: pytest.fail("made hypothesis's"))
    assert _run(port, planned=True) == hypothesis_s_


def test_a_planned_run_stores_its_plan_once_hypothesis_is_its_own(store, monkeypatch) -> None:
    """A run that drew stores what it drew when its hypothesis was loaded without the
    environment's plugins; one whose hypothesis came from elsewhere stores nothing."""
    exploration.forget_plans()  # hypothesis draws (and no stored plan is sent) ...
    monkeypatch.setattr(store, "reading", True)  # ... but this store is read
    monkeypatch.setattr(exploration, "_DRAWS_ALONE", False)
    _run("sim", planned=True)
    assert not store.path.exists()
    monkeypatch.setattr(exploration, "_DRAWS_ALONE", True)
    _run("sim", planned=True)
    foreign = exploration_steps.foreign_addresses(_session("sim"))
    assert store.load(plan_key(foreign, 10, 25)) == _drawn(foreign)


def test_a_callers_junk_strategy_is_never_stored_nor_sent_from_the_store(store, monkeypatch):
    from hypothesis import strategies as st

    key = _store_the_plan_of("sim", store)
    assert exploration._plan_key(_session("sim"), 10, 25) == key
    monkeypatch.setattr(exploration, "JUNK", st.sampled_from(["M", "XX"]))
    assert exploration._plan_key(_session("sim"), 10, 25) is None


def test_forget_plans_sends_nothing_stored(store) -> None:
    key = _store_the_plan_of("sim", store)
    assert store.load(key) is not None
    exploration.forget_plans()
    assert store.load(key) is None


def test_the_key_changes_with_what_the_draws_read(tmp_path, monkeypatch) -> None:
    key = plan_key(["9", "z", "y"], 10, 25)
    assert key is not None and key == plan_key(["9", "z", "y"], 10, 25)
    others = {plan_key(["z", "y"], 10, 25), plan_key(["9", "z", "y"], 11, 25),
              plan_key(["9", "z", "y"], 10, 24)}  # fmt: skip
    assert key not in others and None not in others and len(others) == 3
    # another hypothesis (its version file), and none at all
    other = tmp_path / "hypothesis"
    other.mkdir()
    (other / "version.py").write_text("__version_info__ = (0, 0, 1)\n")
    spec = SimpleNamespace(origin=str(other / "__init__.py"))
    monkeypatch.setattr(exploration_plans.importlib.util, "find_spec", lambda name: spec)
    assert plan_key(["9", "z", "y"], 10, 25) not in (key, None)
    monkeypatch.setattr(exploration_plans.importlib.util, "find_spec", lambda name: None)
    assert plan_key(["9", "z", "y"], 10, 25) is None


def test_the_key_changes_with_the_sources_of_the_draws(tmp_path, monkeypatch) -> None:
    """Each source the draws depend on is in the key (a copy of the package where one of
    them has a byte more gives another key)."""
    package = Path(exploration_plans.__file__).resolve().parent.parent
    key = plan_key(["9"], 10, 25)
    for source in exploration_plans.SOURCES:
        copy = tmp_path / source.replace("/", "_")
        copy.mkdir()
        for each in exploration_plans.SOURCES:
            (copy / each).parent.mkdir(parents=True, exist_ok=True)
            text = (package / each).read_bytes()
            (copy / each).write_bytes(text + b"\n" if each == source else text)
        fake = copy / "sensor" / "exploration_plans.py"
        monkeypatch.setattr(exploration_plans, "__file__", str(fake))
        assert plan_key(["9"], 10, 25) not in (key, None), source
    assert "sensor/exploration_machine.py" in exploration_plans.SOURCES


def test_a_damaged_or_foreign_file_draws_afresh(store) -> None:
    key = _store_the_plan_of("sim", store)
    good = store.path.read_text()
    assert '"brk"' in good and '"format": 1' in good
    damaged = (good.replace('"brk"', '"explode"'), good.replace('"format": 1', '"format": 2'))
    for bad in ("", "{", "[]", json.dumps({"format": 99, "plans": {}}), *damaged):
        store.path.write_text(bad)
        assert store.load(key) is None, bad[:40]
    assert as_plan([[["pause", {"seconds": 1}]]]) is None  # an int: not what was drawn
    assert as_plan([[["pause", {"seconds": 0.05}]]]) == ((("pause", {"seconds": 0.05}),),)


def test_nothing_is_stored_where_bytecode_is_not_written(store, monkeypatch) -> None:
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    assert not store.store("k", ((("brk", {}),),))
    assert not store.path.exists()
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    assert store.store("k", ((("brk", {}),),)) and store.load("k") == ((("brk", {}),),)


#: the CLI as ``sdi12-conform`` runs it, its plans stored in argv[2], the module table
#: written to argv[1] at exit
CLI_WITH_STORE = """
import atexit, json, sys
from pathlib import Path
out, folder = sys.argv.pop(1), sys.argv.pop(1)
from conformance.sensor import exploration_plans
exploration_plans.STORE.folder = Path(folder)
atexit.register(lambda: open(out, "w").write(json.dumps(sorted(sys.modules))))
from conformance.cli import main
main()
"""


def test_a_process_with_a_stored_plan_loads_no_hypothesis(tmp_path) -> None:
    """The first ``--port sim`` process of the exploration case draws its plan and stores
    it; the next sends it with no hypothesis loaded, and judges and writes the same."""
    import os

    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    runs = []
    for n in (1, 2):
        listed = tmp_path / f"modules{n}.json"
        done = subprocess.run(
            [sys.executable, "-c", CLI_WITH_STORE, str(listed), str(tmp_path / "plans"),
             "--port", "sim", "-k", "test_random_command_sequences or test_query_address",
             "--report-dir", str(tmp_path / f"run{n}"), "--plan", "never"],
            capture_output=True, text=True, timeout=180, cwd=tmp_path, env=env,
        )  # fmt: skip
        assert done.returncode == 0, done.stdout + done.stderr
        loaded = set(json.loads(listed.read_text()))
        lines = (tmp_path / f"run{n}" / "transcript.jsonl").read_text().splitlines()
        verdicts = json.loads((tmp_path / f"run{n}" / "verdicts.json").read_text())
        judged = [(r["id"], r["verdict"]) for r in verdicts["requirements"]]
        runs.append((loaded, lines[1:], judged))
    assert "hypothesis" in runs[0][0] and list((tmp_path / "plans").glob("exploration_plans*"))
    assert "hypothesis" not in runs[1][0] and "conformance.sensor.exploration_steps" in runs[1][0]
    assert runs[1][1] == runs[0][1] and len(runs[0][1]) > 1000
    assert runs[1][2] == runs[0][2] and len(runs[0][2]) > 5
