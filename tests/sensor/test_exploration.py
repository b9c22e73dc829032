"""The exploration sends the same sequences whatever else the process has imported:
hypothesis mixes the constants of loaded non-library modules into its draws, so a run in a
pytest process with other test modules loaded explored differently from the CLI's run."""

from __future__ import annotations

import importlib.util
import sys

from conformance.ports import open_sim, parse_sim
from conformance.sensor import exploration
from conformance.sensor.session import SensorSession


def _explored() -> list[str]:
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


def _machine_and_test():
    """A fresh exploration machine class and the test function hypothesis makes of it, as a
    run makes them (a new class per run)."""
    from hypothesis.stateful import get_state_machine_test

    from conformance.sensor.exploration_machine import junk_strategy, machine_class
    from conformance.sensor.exploration_record import Exploration

    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    machine = machine_class(session, Exploration(), None, junk_strategy())
    test = get_state_machine_test(machine).hypothesis.inner_test
    return machine, test


def test_kept_digests_are_hypothesis_own():
    """The digests kept per process (``digests_kept``) are the ones hypothesis computes for
    each run's new machine class and test function, and the same object kind of a changed
    signature gets its own."""
    from hypothesis import core, stateful
    from hypothesis.internal.reflection import function_digest

    first, second = _machine_and_test(), _machine_and_test()
    assert first[0] is not second[0]
    with exploration.digests_kept():
        assert stateful.function_digest is core.function_digest is not function_digest
        kept = [stateful.function_digest(obj) for pair in (first, second) for obj in pair]
        assert len(exploration._DIGESTS) >= 2
    assert stateful.function_digest is core.function_digest is function_digest
    own = [function_digest(obj) for pair in (first, second) for obj in pair]
    assert kept == own
    assert kept[0] != kept[1]  # the class and the test function: two digests

    def plain(a: int) -> None: ...

    def other(a: int, b: int = 2) -> None: ...

    with exploration.digests_kept():
        assert stateful.function_digest(plain) == function_digest(plain)
        assert stateful.function_digest(other) == function_digest(other)
    assert exploration.digest_key(plain) != exploration.digest_key(other)
    assert exploration.digest_key(object()) is None


def test_an_exploration_digests_its_machine_once_a_process(monkeypatch):
    """A second exploration in the process asks hypothesis for no digest: the source of
    the machine and of its test is read once."""
    from hypothesis.internal import reflection

    asked = []
    original = reflection.function_digest

    def counted(function):
        asked.append(function)
        return original(function)

    first = _explored()
    exploration._DIGESTS.clear()
    from hypothesis import core, stateful

    monkeypatch.setattr(stateful, "function_digest", counted)
    monkeypatch.setattr(core, "function_digest", counted)
    assert _explored() == first
    assert len(asked) == 2  # the class and its test, once
    assert _explored() == first
    assert len(asked) == 2
