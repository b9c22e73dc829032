"""tests/support/shared_runs.py: a run is made once however many tests and processes ask, each
test gets a copy of its own, and a run that wrote nothing is an error, not a folder to read.
The main command is stood in for (it writes a verdicts.json and counts its calls), so these
take milliseconds."""

from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

import pytest

from tests.support import shared_runs


class FakeMain:
    """Writes a verdicts.json naming the port, counts its calls in ``calls`` (a file, so
    that forked processes add to it too), exits 1 for a faulty port."""

    def __init__(self, calls: Path, pause: float = 0.0, write: bool = True) -> None:
        self.calls, self.pause, self.write = calls, pause, write

    def __call__(self, argv: list[str]) -> int:
        with self.calls.open("a") as calls:
            calls.write("x")
        time.sleep(self.pause)  # long enough for a second process to ask meanwhile
        folder = Path(argv[argv.index("--report-dir") + 1])
        if self.write:
            folder.mkdir(parents=True)
            (folder / "verdicts.json").write_text(argv[argv.index("--port") + 1])
        return 1 if "faults" in argv[argv.index("--port") + 1] else 0


def test_a_run_is_made_once_and_each_test_gets_its_own_copy(
    tmp_path, tmp_path_factory, monkeypatch
):
    calls = tmp_path / "calls"
    monkeypatch.setattr(shared_runs, "main", FakeMain(calls))
    monkeypatch.setattr(shared_runs, "common_folder", lambda _factory: tmp_path / "common")
    (tmp_path / "common").mkdir()
    first, code = shared_runs.copied_run(tmp_path_factory, tmp_path / "a", "sim://?faults=x")
    (first / "capture.sr").write_text("written beside the run by this test")
    again, code_again = shared_runs.copied_run(tmp_path_factory, tmp_path / "b", "sim://?faults=x")
    other, clean_code = shared_runs.copied_run(tmp_path_factory, tmp_path / "c", "sim", "recorder")
    assert calls.read_text() == "xx"  # the faulty sensor run once, the recorder run once
    assert (code, code_again, clean_code) == (1, 1, 0)
    assert (again / "verdicts.json").read_text() == "sim://?faults=x"
    assert not (again / "capture.sr").exists()  # the first test's file stayed in its copy
    assert (other / "verdicts.json").read_text() == "sim"


def _ask(common: Path, calls: Path, into: Path) -> None:
    shared_runs.main = FakeMain(calls, pause=0.3)  # type: ignore[assignment]
    shared_runs.common_folder = lambda _factory: common  # type: ignore[assignment]
    shared_runs.copied_run(None, into, "sim")  # type: ignore[arg-type]


def test_processes_asking_at_once_wait_for_the_one_run(tmp_path):
    common, calls = tmp_path / "common", tmp_path / "calls"
    common.mkdir()
    fork = multiprocessing.get_context("fork")
    asking = [
        fork.Process(target=_ask, args=(common, calls, tmp_path / f"copy{n}")) for n in range(3)
    ]
    for process in asking:
        process.start()
    for process in asking:
        process.join(30)
    assert [p.exitcode for p in asking] == [0, 0, 0]
    assert calls.read_text() == "x"
    assert all((tmp_path / f"copy{n}" / "verdicts.json").read_text() == "sim" for n in range(3))


def test_a_run_that_wrote_nothing_is_an_error_and_is_tried_again(
    tmp_path, tmp_path_factory, monkeypatch
):
    calls = tmp_path / "calls"
    monkeypatch.setattr(shared_runs, "common_folder", lambda _factory: tmp_path)
    monkeypatch.setattr(shared_runs, "main", FakeMain(calls, write=False))
    with pytest.raises(AssertionError, match="wrote no verdicts.json"):
        shared_runs.made_run(tmp_path_factory, "sim")
    monkeypatch.setattr(shared_runs, "main", FakeMain(calls))
    folder, code = shared_runs.made_run(tmp_path_factory, "sim")
    assert code == 0 and (folder / "verdicts.json").read_text() == "sim"
    assert calls.read_text() == "xx"
