"""The exploration sends the same sequences whatever else the process has imported:
hypothesis mixes the constants of loaded non-library modules into its draws, so a run in a
pytest process with other test modules loaded explored differently from the CLI's run."""

from __future__ import annotations

import contextlib
import importlib.util
import sys

from conformance.ports import open_sim, parse_sim
from conformance.sensor import exploration
from conformance.sensor.session import SensorSession


def _explored() -> list[str]:
    exploration.forget_plans()  # hypothesis draws afresh: what these tests are about
    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return exploration.explore(session).log  # the sequences a run sends


def _load_module_full_of_constants(folder) -> None:
    """A local module whose constants a draw could pick: strings of the junk alphabet, small
    integers and floats."""
    junk = [f'"{a}{b}{c}"' for a in "MDCR" for b in "0123" for c in "+-._"]
    numbers = [str(n) for n in range(2, 400, 7)] + [f"{n / 8}" for n in range(1, 60)]
    path = folder / "sdi12_local_constants.py"
    path.write_text(f"JUNK = [{', '.join(junk)}]\nNUMBERS = [{', '.join(numbers)}]\n")
    spec = importlib.util.spec_from_file_location("sdi12_local_constants", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["sdi12_local_constants"] = module
    spec.loader.exec_module(module)


def test_the_exploration_does_not_depend_on_the_modules_loaded(tmp_path):
    before = _explored()
    _load_module_full_of_constants(tmp_path)
    try:
        assert _explored() == before
    finally:
        sys.modules.pop("sdi12_local_constants", None)


def test_the_database_key_changes_nothing_drawn(monkeypatch):
    """With a fixed example-database key (there is no database) the exploration sends what it
    sent with hypothesis's digest of the sources, and digests no source."""
    from hypothesis import core, stateful
    from hypothesis.internal import reflection

    digested: list[str] = []
    clean = reflection._clean_source  # what function_digest alone calls, per source it reads
    monkeypatch.setattr(reflection, "_clean_source", lambda src: digested.append(src) or clean(src))
    with_key = _explored()
    assert digested == []
    monkeypatch.setattr(exploration, "no_database_key", contextlib.nullcontext)
    assert _explored() == with_key
    assert len(digested) == 2  # the plain way digests the machine and its runner
    assert core.function_digest is stateful.function_digest is reflection.function_digest


#: a fresh interpreter (hypothesis not loaded yet): the groups of entry points read while the
#: exploration's machine loads, and the plugin switch as the user had it afterwards
LOADS_MACHINE = """
import importlib.metadata as metadata, json, os
asked = []
real = metadata.entry_points
def entry_points(**selection):
    asked.append(selection.get("group"))
    return real(**selection)
metadata.entry_points = entry_points
from conformance.sensor import exploration
exploration._machine_module()
import hypothesis
print(json.dumps([asked, os.environ.get("HYPOTHESIS_NO_PLUGINS")]))
"""


def test_the_machine_loads_hypothesis_without_the_environments_plugins() -> None:
    """The exploration's hypothesis reads no entry-point plugin of the environment (as the
    judged session loads no pytest plugin it does not name), and the switch that says so is
    gone again once hypothesis is loaded."""
    import json
    import os
    import subprocess

    env = {k: v for k, v in os.environ.items() if k != "HYPOTHESIS_NO_PLUGINS"}
    done = subprocess.run(
        [sys.executable, "-c", LOADS_MACHINE], capture_output=True, text=True, env=env,
        check=True, timeout=120,
    )  # fmt: skip
    asked, switch = json.loads(done.stdout.strip().splitlines()[-1])
    assert "hypothesis" not in asked and switch is None, done.stdout


def test_an_exploration_keeps_nothing_of_its_run_alive() -> None:
    """The exploration's machine class outlives its run in hypothesis's per-class cache; the
    run's session (and through it the link, the transcript and its views) must not: a fault
    matrix's worker making 125 runs in one process grew to 3.7 GB and its collections walked
    every kept run again (wrong-crc's row: 3 s alone, 8.9 s after 124 others)."""
    import gc
    import weakref

    from hypothesis.stateful import RuleBasedStateMachine

    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    record = exploration.explore(session)
    assert record.log  # it did explore
    gone = weakref.ref(session), weakref.ref(opened.link.transcript)
    del session, opened, record
    gc.collect()
    assert [ref() for ref in gone] == [None, None]
    kept = getattr(RuleBasedStateMachine, "_setup_state_per_class", {})
    assert not any("sensor" in vars(machine) for machine in kept)
