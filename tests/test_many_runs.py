"""conformance.many_runs: runs judged in one pytest session give the verdicts, findings,
details, exit statuses and report files that each run in a session of its own gives (live,
cut short by ``pytest.exit``, replayed from a capture), in any order; a run the session
cannot judge as its own session would is judged in one of its own."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance import many_runs
from conformance.conduct import conduct
from conformance.matrices.roundtrip import judged_events, live_run, row_through_capture
from conformance.matrices.sensor_matrix import fault_port, run_rows
from conformance.run import RunOptions
from tests.support.steady_verdicts import steady

#: a run cut short before any case (no device at address 7), a fault of version 1.3, a
#: fault's run, a clean run: each after the others in one session
RUNS = (
    {"port": "sim", "address": "7"},
    {"port": fault_port(("v13-concurrent-over-20", (), "13", ()))},
    {"port": fault_port(("never-standby", (), "14", ()))},
    {"port": "sim"},
)


def one_run(folder: Path, served: list[bool], **options: object) -> tuple[int, object, list]:
    """A run as a matrix row makes it (no HTML, no files), its status, steady verdict lines
    and whether a session serving many judged it."""
    folder.mkdir(parents=True)
    given = RunOptions(report_dir=str(folder), **options)  # type: ignore[arg-type]
    served.append(many_runs.serving(given, None, False, False, (), False) is not None)
    result = conduct(given, html=False, rootdir=folder, files=())
    assert result.run is not None
    return result.pytest_code, steady(result.run.verdict_lines()), result.run.stop_reason


def test_runs_in_one_session_equal_sessions_of_their_own(tmp_path):
    served: list[bool] = []
    alone = [one_run(tmp_path / f"alone{i}", served, **o) for i, o in enumerate(RUNS)]
    assert served == [False] * len(RUNS)
    served.clear()
    together = many_runs.judged_in_one_session(
        lambda: [one_run(tmp_path / f"together{i}", served, **o) for i, o in enumerate(RUNS)]
    )
    assert served == [True] * len(RUNS)
    assert together == alone
    assert alone[0][0] == 5 and "no device answered" in alone[0][2]  # cut short by pytest.exit
    assert alone[3][1]["summary"]["verdict"] == "COMPLIANT"


def test_report_files_written_in_one_session_are_a_session_of_its_own(tmp_path):
    def written(folder: Path) -> dict[str, object]:
        folder.mkdir()
        conduct(RunOptions(port="sim", report_dir=str(folder)), html=False, rootdir=folder)
        found = {p.name: p.read_bytes() for p in sorted(folder.iterdir())}
        found["verdicts.json"] = steady(json.loads(found["verdicts.json"]))
        found.pop("transcript.jsonl")  # its first line holds the start time
        return found

    alone = written(tmp_path / "alone")
    together = many_runs.judged_in_one_session(lambda: written(tmp_path / "together"))
    assert together.keys() == alone.keys() and "verdicts.json" in alone
    assert together == alone


def test_a_replayed_capture_in_one_session_is_judged_as_in_its_own(tmp_path):
    def both(folder: Path) -> tuple[object, object]:
        lines, events = live_run(folder / "live", fault_port(("slow-wake", (), "14", ())))
        return steady(lines), steady(judged_events(events, "row", folder))

    alone = both(tmp_path / "alone")
    together = many_runs.judged_in_one_session(lambda: both(tmp_path / "together"))
    assert together == alone
    assert alone[1]["run"]["link"]["kind"].startswith("replay")


def test_a_run_of_another_selection_gets_a_session_of_its_own(tmp_path):
    served: list[bool] = []
    alone = one_run(tmp_path / "alone", served, port="sim", keyword="crc")
    together = many_runs.judged_in_one_session(
        lambda: one_run(tmp_path / "together", served, port="sim", keyword="crc")
    )
    assert served == [False, False]
    assert together == alone
    assert sum(r["verdict"] == "PASS" for r in alone[1]["requirements"]) < 10  # -k crc only


def test_the_works_exception_reaches_its_caller():
    def work() -> None:
        raise LookupError("from the work")

    with pytest.raises(LookupError, match="from the work"):
        many_runs.judged_in_one_session(work)


def test_matrix_rows_made_in_batches_are_the_rows_made_alone():
    from conformance.emulator import FAULTS

    names = ["wrong-crc", "slow-wake", "v13-concurrent-over-20"]
    items = [(n, tuple(FAULTS[n].violates), FAULTS[n].version, ()) for n in names]
    alone = run_rows(items, row_through_capture, 1)
    assert run_rows(items, row_through_capture, 1, role="sensor") == alone
    assert run_rows(items, row_through_capture, 2, role="sensor") == alone
    assert all(row.exact for row in alone)


def test_a_run_its_options_refuse_gets_a_session_of_its_own(tmp_path):
    def refused(folder: Path) -> tuple[bool, int, bool]:
        folder.mkdir()
        given = RunOptions(port="sim", address="!!", report_dir=str(folder))
        served = many_runs.serving(given, None, False, False, (), False) is not None
        result = conduct(given, html=False, rootdir=folder, files=())
        return served, result.pytest_code, result.run is None

    alone = refused(tmp_path / "alone")
    assert many_runs.judged_in_one_session(lambda: refused(tmp_path / "together")) == alone
    assert alone == (False, int(pytest.ExitCode.USAGE_ERROR), True)
