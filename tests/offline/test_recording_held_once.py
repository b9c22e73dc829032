"""A passive judgement of a capture holds one list of its events, not three (issue 22,
bounded memory): ``decode_capture(keep=False)`` hands the decode it kept over instead of
copying it, the recording link's transcript is the decode's own list, and the report's
``transcript.jsonl`` of a loaded recording is written without a kept copy. Each gives what
the way it replaces gave: the same events, the same file, the same decode on a later call."""

from __future__ import annotations

from pathlib import Path

import pytest

import conformance.capture.decode as capture_decode
import conformance.replay.recording as recording
from conformance.capture import decode_capture
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from tests.offline.test_judge_memory import busy_capture


@pytest.fixture
def capture(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setattr(capture_decode, "_LAST", None)
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.05)  # three seconds of a busy bus
    return path


def test_a_kept_decode_is_handed_over_once_and_equal(capture: Path):
    first = decode_capture(str(capture))  # as ``judge`` decodes to decide replay or not
    assert capture_decode._LAST is not None
    kept = capture_decode._LAST[1]
    taken = decode_capture(str(capture), keep=False)
    assert taken is kept and capture_decode._LAST is None  # handed over, not kept too
    assert taken.events == first.events and taken.events is not first.events
    assert taken.notes == first.notes and (taken.chars, taken.breaks) == (first.chars, first.breaks)
    again = decode_capture(str(capture), keep=False)  # nothing kept: decoded again, the same
    assert again is not taken and again.events == first.events
    assert capture_decode._LAST is None


def test_the_recording_link_holds_the_decode_once(capture: Path):
    reference = decode_capture(str(capture))
    link = load_recording(parse_recording(recording_port(str(capture), "sr")))
    assert list(link.transcript.events) == reference.events  # (a compact store of them)
    assert link.decoded is not None and link.decoded.events == []  # given to the transcript
    assert list(link.decoded.baud_error_pct) == list(reference.baud_error_pct)
    assert capture_decode._LAST is None
    assert not link.keeps_written_reading


def test_an_unkept_recording_is_the_same_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(recording, "_READ", {})
    events = decode_capture(str(_small_capture(tmp_path))).events
    kept, unkept = tmp_path / "kept.jsonl", tmp_path / "unkept.jsonl"
    recording.write_recording(kept, events)
    assert len(recording._READ) == 1
    recording.write_recording(unkept, events, keep=False)
    assert len(recording._READ) == 1  # nothing more kept
    assert unkept.read_bytes() == kept.read_bytes()
    assert recording.read_recording(unkept).events == list(events)


def _small_capture(tmp_path: Path) -> Path:
    path = tmp_path / "small.sr"
    busy_capture(path, 0.03)
    return path
