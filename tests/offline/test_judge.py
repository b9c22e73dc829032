"""``judge`` and ``export`` (issue 11): a saved run judged again gives the run's own verdicts,
by replay of its transcript and through a logic-analyzer capture of it; bad recordings are
refused with the file named and exit 4.

Every sensor and recorder fault goes through a capture in the fault matrices
(``tests/matrices/test_sensor_matrix.py``, ``tests/matrices/test_recorder_matrix.py``); here
the default selection keeps one clean and one faulty run per role.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Callable
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.replay.recording import OPTIONS_NOTE, read_recording
from tests.support.shared_runs import copied_run

EXIT_USAGE = 4


def requirements(run: Path) -> dict[str, dict]:
    data = json.loads((run / "verdicts.json").read_text(encoding="utf-8"))
    return {r["id"]: r for r in data["requirements"]}


Live = Callable[..., Path]


@pytest.fixture
def live(tmp_path_factory: pytest.TempPathFactory, tmp_path: Path) -> Live:
    """``live(port, role="sensor")``: this test's copy (``tmp_path/live``) of the session's
    live run of ``role`` against ``port`` (tests/support/shared_runs.py: the clean sensor's
    run was made four times in this module and again in others)."""

    def run(port: str, role: str = "sensor") -> Path:
        out, _code = copied_run(tmp_path_factory, tmp_path / "live", port, role)
        assert (out / "verdicts.json").exists()
        return out

    return run


def wire_lines(run: Path) -> list[str]:
    """The transcript without the run-options note (which names the run's own port)."""
    lines = (run / "transcript.jsonl").read_text(encoding="utf-8").splitlines()
    return [line for line in lines if OPTIONS_NOTE not in line]


def same_verdicts(first: Path, again: Path, *, uncertainty_may_differ: bool = False) -> None:
    a, b = requirements(first), requirements(again)
    assert a.keys() == b.keys()
    verdicts = {
        k: (a[k]["verdict"], b[k]["verdict"]) for k in a if a[k]["verdict"] != b[k]["verdict"]
    }
    assert not verdicts, verdicts
    if not uncertainty_may_differ:
        assert a == b


@pytest.mark.parametrize(
    ("port", "role"),
    [
        ("sim", "recorder"),
        pytest.param("sim", "sensor", marks=pytest.mark.slow),
        pytest.param("sim://?faults=no-service-request", "sensor", marks=pytest.mark.slow),
        pytest.param(
            "sim://?recorder-faults=retry-too-early",
            "recorder",
            marks=[
                pytest.mark.slow,
                # its 12 ms retry runs into the 15 ms reply of scenario reply-at-window-edge;
                # replayed, the played sensor starts that reply one character later than it
                # did live (the replay does not yet reproduce a collision exactly), and
                # R-7.0-13's worst gap differs (FAIL both times). Strict: the day the replay
                # reproduces collisions this passes and the mark must go.
                pytest.mark.xfail(reason="replay of a mid-command collision diverges", strict=True),
            ],
        ),
    ],
)
def test_replayed_transcript_gives_the_runs_verdicts(tmp_path, live, port, role):
    first = live(port, role)
    again = tmp_path / "again"
    code = main(["judge", str(first / "transcript.jsonl"), "--report-dir", str(again)])
    assert code in (0, 1)
    same_verdicts(first, again)
    assert wire_lines(first) == wire_lines(again)  # the same bus, event for event
    link = json.loads((again / "verdicts.json").read_text())["run"]["link"]
    assert link["kind"] == "replay of sim"


@pytest.mark.slow
def test_a_run_records_how_it_was_made(live):
    first = live("sim://?version=1.3")
    recording = read_recording(first)
    assert recording.options["port"] == "sim://?version=1.3"
    assert recording.options["link"]["virtual_time"] is True
    assert recording.role == "sensor"


@pytest.mark.slow
def test_a_replay_that_no_longer_matches_stops_and_says_where(tmp_path, live):
    """A recorder-role recording cannot answer the sensor cases: the run stops (INCOMPLETE,
    exit 3) naming what the tool sent and what the recording has, never invented answers."""
    first = live("sim", "recorder")
    out = tmp_path / "wrong"
    code = main(["--port", f"replay:{first}", "--report-dir", str(out)])
    assert code == 3
    data = json.loads((out / "verdicts.json").read_text())
    assert "replay diverged" in data["run"]["stop_reason"]
    assert data["summary"]["counts"]["PASS"] == 0


@pytest.mark.slow
def test_capture_of_a_run_gives_its_verdicts(tmp_path, live):
    """Export to .sr with the tool's TX channel, judge the capture: the run's verdicts, with
    the capture's own uncertainty (one sample period) in the timing figures."""
    first = live("sim://?faults=response-too-early")
    capture = tmp_path / "run.sr"
    assert main(["export", str(first), "--to", "sr", "--tool-channel", "-o", str(capture)]) == 0
    with zipfile.ZipFile(capture) as zf:
        assert "metadata" in zf.namelist()
    again = tmp_path / "capture"
    code = main(["judge", str(capture), "--tx-channel", "TOOL_TX", "--report-dir", str(again)])
    assert code == 1
    same_verdicts(first, again, uncertainty_may_differ=True)
    assert (again / "capture.jsonl").exists()
    link = json.loads((again / "verdicts.json").read_text())["run"]["link"]
    assert 0 < link["timing_uncertainty_ms"] <= 0.05  # 10 us samples, measured per edge


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["vcd", "csv"])
def test_export_formats_open_again(tmp_path, live, fmt):
    first = live("sim")
    out = tmp_path / f"run.{fmt}"
    assert main(["export", str(first), "--to", fmt, "-o", str(out)]) == 0
    text = out.read_text(encoding="ascii")
    if fmt == "vcd":
        assert "$comment sdi12-conform-capture" in text  # the run's options travel with it
    else:
        assert text.startswith("Time [s],SDI12")


def _bad(tmp_path: Path, name: str, content: bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(content)
    return path


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("empty.sr", b"", "empty file"),
        ("garbage.bin", bytes(range(256)) * 8, "binary data"),
        ("cut.sr", b"PK\x03\x04" + b"\x00" * 40, "cut.sr"),
        ("notjson.jsonl", b"{not json\n", "line 1"),
        ("quiet.jsonl", b"", "empty file"),
    ],
)
def test_bad_recordings_are_refused_plainly(tmp_path, capsys, name, content, words):
    path = _bad(tmp_path, name, content)
    assert main(["judge", str(path), "--report-dir", str(tmp_path / "out")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert str(path) in err and words in err
    assert "Traceback" not in err


@pytest.mark.parametrize("name", ["verdicts.json", "junit.xml", "report.html"])
def test_a_run_s_report_given_as_the_recording_names_what_to_pass(tmp_path, capsys, name):
    """First-hour look (2026-12-05): ``judge RUN/verdicts.json`` said "line 1: not a
    transcript event (Expecting property name enclosed in double quotes ...)"."""
    (tmp_path / "transcript.jsonl").write_text("", encoding="utf-8")
    report = _bad(tmp_path, name, b'{\n "schema": "sdi12-conform/verdicts/1"\n}\n')
    assert main(["judge", str(report), "--report-dir", str(tmp_path / "out")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "a report of a run, not a recording" in err, err
    assert str(tmp_path / "transcript.jsonl") in err, err


@pytest.mark.slow
def test_missing_recording_and_wrong_channel(tmp_path, live, capsys):
    assert main(["judge", str(tmp_path / "nothing.sr")]) == EXIT_USAGE
    assert "nothing.sr" in capsys.readouterr().err
    first = live("sim")
    capture = tmp_path / "run.sr"
    assert main(["export", str(first), "--to", "sr", "-o", str(capture)]) == 0
    code = main(["judge", str(capture), "--channel", "D7", "--run", str(first)])
    assert code == EXIT_USAGE
    err = capsys.readouterr().err
    assert "D7" in err and "SDI12" in err  # names the channels that are there


def test_export_refuses_what_it_cannot_write(tmp_path, capsys):
    assert main(["export", str(tmp_path / "none"), "--to", "sr"]) == EXIT_USAGE
    assert "no such file" in capsys.readouterr().err


# Every sensor and recorder fault through a capture: the fault matrices
# (tests/matrices/test_sensor_matrix.py, tests/matrices/test_recorder_matrix.py) judge each run
# through its .sr too.
