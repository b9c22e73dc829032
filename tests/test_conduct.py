"""One run, in this process (issue 21): the CLI, ``judge`` (replay and passive) and the
matrices hand a RunOptions to :func:`conformance.conduct.conduct`; nothing is spelled out as
flags and parsed back, no subprocess starts, and no verdicts.json is read back."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from conformance import options as options_module
from conformance.cli import main
from conformance.conduct import conduct
from conformance.exits import EXIT_COMPLIANT, EXIT_NON_COMPLIANT
from conformance.run import GivenOptions, RunOptions


@pytest.fixture
def handed(monkeypatch) -> list[RunOptions]:
    """Every RunOptions handed to a run; reading the plugin's flags, starting a subprocess
    or reading a verdicts.json back fail the test."""
    seen: list[RunOptions] = []
    init = GivenOptions.__init__

    def keep(self, options: RunOptions) -> None:
        seen.append(options)
        init(self, options)

    def refuse(*args, **kwargs):
        raise AssertionError(f"not on the conduct path: {args!r}")

    read_text = Path.read_text

    def no_verdicts_read(self: Path, *args, **kwargs) -> str:
        """A run's own verdicts.json is never read back (a recording's, being judged, is)."""
        written = {Path(o.report_dir or "").resolve() for o in seen}
        read_back = self.name == "verdicts.json" and self.resolve().parent in written
        assert not read_back, f"verdicts read back from {self}"
        return read_text(self, *args, **kwargs)

    monkeypatch.setattr(GivenOptions, "__init__", keep)
    monkeypatch.setattr(options_module, "run_option_values", refuse)
    monkeypatch.setattr(subprocess, "Popen", refuse)
    monkeypatch.setattr(Path, "read_text", no_verdicts_read)
    return seen


def test_the_main_command_hands_its_options_to_one_run(handed, tmp_path):
    code = main(["--port", "sim", "--report-dir", str(tmp_path), "-k", "identification",
                 "--sdi-version", "1.3"])  # fmt: skip
    assert code == EXIT_COMPLIANT
    [given] = handed
    assert (given.port, given.keyword, given.version) == ("sim", "identification", "1.3")
    written = json.loads((tmp_path / "verdicts.json").open(encoding="utf-8").read())
    assert written["run"]["port"] == "sim" and written["dut"]["sdi12_version"] == "1.3"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> Path:
    """A faulty run's folder, made before any guard is in place (judging reads it)."""
    run = tmp_path_factory.mktemp("recorded") / "run"
    assert main(["--port", "sim://?faults=crc-missing", "--report-dir", str(run),
                 "-k", "crc"]) == EXIT_NON_COMPLIANT  # fmt: skip
    return run


def test_judge_replays_and_judges_passively_through_the_same_entry_point(
    recorded, handed, tmp_path
):
    run = recorded
    again = tmp_path / "again"
    assert main(["judge", str(run), "--report-dir", str(again)]) == EXIT_NON_COMPLIANT
    passive = tmp_path / "passive"
    assert main(["judge", str(run), "--passive", "--role", "sensor",
                 "--report-dir", str(passive)]) == EXIT_NON_COMPLIANT  # fmt: skip
    ports = [o.port for o in handed]
    assert ports[0] == f"replay:{run / 'transcript.jsonl'}" and handed[0].keyword == "crc"
    assert ports[1].startswith("recording:") and handed[1].role == "sensor"


def test_the_matrix_runs_through_it_too(handed):
    from conformance.conduct import run_once

    data = run_once("sim://?faults=crc-missing", keyword="crc")
    assert data["summary"]["verdict"] == "NON-COMPLIANT"
    assert [o.keyword for o in handed] == ["crc"]


def test_a_run_without_a_folder_gets_one_of_its_own(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    result = conduct(RunOptions(keyword="test_query_address"), html=False)
    assert result.report_dir.parent == Path("reports") and result.exit_code == EXIT_COMPLIANT
    assert (tmp_path / result.report_dir / "verdicts.json").exists()


def test_a_finished_run_is_freed_by_reference_counting(tmp_path):
    """Issue 22 (fault-matrix CPU): pytest's config, session and items hold each other in
    reference cycles; a run they still reference after pytest.main returns lives until a
    full collection walks it (10^5 events for a CRC fault). With the collector off, the run
    must die the moment its caller drops it, its transcript's events with it."""
    import gc
    import weakref

    options = RunOptions(port="sim", report_dir=str(tmp_path), keyword="test_query_address or crc")
    was_on = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        result = conduct(options, html=False, rootdir=tmp_path, files=())
        run = result.run
        assert run is not None and run.verdict_lines() is not None
        assert run.link is not None and run.link.transcript.events
        run_ref = weakref.ref(run)
        record_ref = weakref.ref(run.cases[0])
        del run, result
        assert run_ref() is None, "the run outlived its caller (held by pytest's cycles)"
        assert record_ref() is None, "a case record outlived the run (held by its item)"
    finally:
        if was_on:
            gc.enable()


#: a conftest.py that would change a judged run it were loaded into: it says it was loaded,
#: drops every case and fails any that is left
MEDDLING_CONFTEST = """
import pathlib
import pytest

pathlib.Path({mark!r}).write_text("loaded")


@pytest.fixture(autouse=True)
def meddle():
    raise RuntimeError("a project's conftest.py reached the judged run")


def pytest_collection_modifyitems(items):
    items.clear()
"""


@pytest.mark.parametrize("where", [".", "tests", "testing"])
def test_a_project_conftest_where_the_tool_starts_is_not_loaded(monkeypatch, tmp_path, where):
    """The judged run loads no conftest.py (``--noconftest``): pytest would otherwise load
    the one in the working folder and in each ``test*`` folder beside it (a checkout's
    ``tests/conftest.py``), and a project's hooks and autouse fixtures would change the
    verdicts of a run started there (as this one's would: every case dropped or failed)."""
    start, mark = tmp_path / "project", tmp_path / "loaded"
    (start / where).mkdir(parents=True, exist_ok=True)
    (start / where / "conftest.py").write_text(MEDDLING_CONFTEST.format(mark=str(mark)))
    monkeypatch.chdir(start)
    out = tmp_path / "out"
    out.mkdir()
    options = RunOptions(port="sim", report_dir=str(out), keyword="test_query_address")
    result = conduct(options, html=False, rootdir=out, files=())
    assert not mark.exists(), f"{where}/conftest.py was loaded into the judged run"
    assert result.run is not None and result.pytest_code == 0
    lines = result.run.verdict_lines()
    assert lines is not None
    judged = {r["id"]: r["verdict"] for r in lines["requirements"] if r["verdict"] != "N/A"}
    assert judged == {"R-4.4.3-01": "PASS"}
