"""A fault-matrix row's round trip hands its decoded capture to the replay in memory (issue
22, matrix CPU): ``plan(..., in_memory=True)`` holds the decoding where a user's ``judge``
writes ``capture.jsonl`` (10^4..10^5 lines a row, deleted with the row: 3% of its CPU), and
the replay reads the same events either way. A user's ``judge`` still writes the file, and
events a file would not read back as exactly are written in the matrix too."""

from __future__ import annotations

import zipfile
from dataclasses import replace
from pathlib import Path

import pytest

import conformance.offline.judge as judge
import conformance.replay.recording as recording
from conformance.capture import held_sr
from conformance.capture.columns import WireColumns
from conformance.capture.export import export_events
from conformance.conduct import conduct
from conformance.matrices import roundtrip
from conformance.replay.recording import RecordingError, options_note, read_recording
from conformance.transcript import DUT, EventKind, wire_event

PORT = "sim://?faults=crc-missing"
KEYWORD = "crc"  # the CRC cases alone: a short run that still FAILs rules


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, list]:
    """The fault's live run: its verdict lines and events."""
    return roundtrip.live_run(tmp_path_factory.mktemp("live"), PORT, keyword=KEYWORD)


def _capture(events: list, folder: Path) -> Path:
    """The run exported as the round trip exports it."""
    folder.mkdir(parents=True, exist_ok=True)
    notes = [e for e in events if e.kind is EventKind.NOTE]
    path = folder / "run.sr"
    export_events(events, str(path), "sr", tool_channel=True, notes=notes)
    return path


def test_the_round_trip_writes_no_decoded_capture(live, tmp_path: Path):
    data, events = live
    again = roundtrip.judged_events(events, "live", tmp_path)
    assert (tmp_path / "run.sr").exists()
    assert not (tmp_path / "capture" / "capture.jsonl").exists()
    assert roundtrip.verdict_changes(data, again) == ()
    assert any(r["verdict"] == "FAIL" for r in again["requirements"])
    assert recording._HELD == {}  # let go with the row


def test_the_round_trip_holds_its_captures_samples(live, tmp_path: Path):
    """The row's .sr holds its metadata and comment, not its 3*10^7 samples: they are held
    as the edges they read back as (capture/held_sr.py) while the row is judged, then let
    go; the verdicts are the live run's (and a user's judge of the written file's, below)."""
    data, events = live
    again = roundtrip.judged_events(events, "live", tmp_path)
    with zipfile.ZipFile(tmp_path / "run.sr") as zf:
        names = zf.namelist()
    assert "metadata" in names and not [n for n in names if n.startswith("logic-1")]
    assert held_sr._HELD == {}
    assert roundtrip.verdict_changes(data, again) == ()


def test_a_users_judge_writes_it_and_judges_alike(live, tmp_path: Path):
    data, events = live
    in_memory = roundtrip.judged_events(events, "live", tmp_path / "matrix")
    capture = _capture(events, tmp_path / "user")
    again = tmp_path / "user" / "again"
    found = judge.plan([str(capture), "--report-dir", str(again)])
    assert found.replay is not None
    assert (again / "capture.jsonl").exists()
    assert any(n.startswith("decoded capture written to") for n in found.notes)
    result = conduct(replace(found.replay, report_dir=str(again)), html=False, rootdir=again)
    assert result.run is not None
    assert result.run.verdict_lines()["requirements"] == in_memory["requirements"]
    assert roundtrip.verdict_changes(data, result.run.verdict_lines()) == ()


def test_events_a_file_would_not_read_back_as_are_written(
    live, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    _data, events = live
    capture = _capture(events, tmp_path)
    monkeypatch.setattr(judge, "plain_fields", lambda e: False)  # as for an int time
    monkeypatch.setattr(WireColumns, "plain", lambda self: False)  # the columns' check too
    with recording.held_recordings():
        found = judge.plan([str(capture), "--report-dir", str(tmp_path / "a")], in_memory=True)
        assert recording._HELD == {}
    assert (tmp_path / "a" / "capture.jsonl").exists()
    assert found.replay is not None


def test_a_held_recording_reads_as_its_file_would_until_let_go(tmp_path: Path):
    options = {"role": "sensor", "address": "0"}
    events = [options_note(options), wire_event(EventKind.CHAR, DUT, 0.1, 0.108, 0x30)]
    path = tmp_path / "capture.jsonl"
    with recording.held_recordings():
        recording.hold_recording(path, events)
        got = read_recording(path)
        assert got.events == events and got.events is not events
        assert got.options == options
        assert not path.exists()
    with pytest.raises(RecordingError, match="no such file"):
        read_recording(path)


def test_the_held_capture_is_the_users_capture_jsonl(live, tmp_path: Path):
    """The thirteenth matrix round: the round trip holds its decoded capture as columns
    (no event made per character); read back, it is the capture.jsonl a user's ``judge``
    writes, event for event, and it gives the replay the sensor and link that file gives."""
    from conformance.replay.link import recorded_sensor, replayed_info
    from conformance.replay.sensor import RecordedSensor

    _data, events = live
    capture = _capture(events, tmp_path)
    judge.plan([str(capture), "--report-dir", str(tmp_path / "user")])
    written = read_recording(tmp_path / "user" / "capture.jsonl")
    with recording.held_recordings():
        found = judge.plan([str(capture), "--report-dir", str(tmp_path / "m")], in_memory=True)
        assert found.replay is not None
        held = read_recording(tmp_path / "m" / "capture.jsonl")
        assert held.held is not None and held._events is None
        assert held.options == written.options
        assert replayed_info(held) == replayed_info(written)
        sensor = recorded_sensor(held)
        assert sensor._replies is None and sensor._tool is None  # columns, no events
        assert held.events == written.events
    user = RecordedSensor(written.events)
    assert (sensor.tool, sensor.replies) == (user.tool, user.replies)
    assert (sensor._needs, sensor._touching) == (user._needs, user._touching)
    for name in ("kind", "wire", "end"):
        assert getattr(sensor, f"_tool_{name}") == getattr(user, f"_tool_{name}")
    for name in ("start", "wire", "length"):
        assert getattr(sensor, f"_reply_{name}") == getattr(user, f"_reply_{name}")
