"""The reports' search of a whole passive run read from the bus pass's windows (issue 22,
``view.windows.WindowedTransmissions`` through ``view.runs.whole_cut``): every segment the
search and ``exchange_behind`` read must be the one the whole view gives (base-s62 cut that
view once for the reports, ``commands/passive.cut_for_reports``), item by item, in order,
read in order or at random, with characters only or all; and no whole view is cut for it.
The recordings: busy-bus captures, the shared real captures, three-sensor bus recordings
(directions inferred) and sim runs with sensor faults (directions given, and taken away)."""

from __future__ import annotations

import random
from dataclasses import replace
from pathlib import Path

import pytest

from conformance.conduct import run_into
from conformance.event_store import CompactEvents
from conformance.links.errors import PortError
from conformance.matrices.sensor_matrix import fault_port
from conformance.offline.sensor_windows import bus_windows
from conformance.replay.recording import read_recording, write_recording
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.transcript import BUS
from conformance.view import runs
from conformance.view.runs import LazyCut, Segment, read_view, whole_cut
from tests.offline.test_judge_memory import busy_capture
from tests.support.bus_of_sensors import record

SHARED = Path("/work/shared/captures")


def _load(path: Path, kind: str):
    return load_recording(parse_recording(recording_port(str(path), kind)))


def _compare(path: Path, kind: str, monkeypatch: pytest.MonkeyPatch) -> int:
    """The whole view's segments (on a load of their own) against the windowed cut's; the
    segments compared (0: both loads refused alike)."""
    try:
        old_link, new_link = _load(path, kind), _load(path, kind)
    except PortError as exc:
        with pytest.raises(PortError, match=str(exc)[:40]):
            _load(path, kind)
        return 0
    whole = read_view(list(old_link.transcript.events)).transmissions
    bus_windows(new_link)
    with monkeypatch.context() as m:  # the windowed cut reads no whole view
        m.setattr(runs, "transcript_view", _refused)
        cut = whole_cut(new_link.transcript)
        assert isinstance(cut, LazyCut)
        assert list(cut) == [Segment.of(t) for t in whole], path
        assert cut.texts() == [t.text for t in whole]
        with_chars = cut.transmissions.with_chars()  # type: ignore[attr-defined]
        assert [Segment.of(t) for t in with_chars] == [Segment.of(t) for t in whole if t.chars]
        picks = random.Random(len(whole)).sample(range(len(whole)), min(40, len(whole)))
        assert [cut[i] for i in picks] == [Segment.of(whole[i]) for i in picks]
        assert cut[-1:] == [Segment.of(t) for t in whole[-1:]]
    assert "_view" not in new_link.transcript.__dict__
    return len(whole)


def _refused(transcript):
    raise AssertionError("a whole view was cut")


def test_busy_bus_captures(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    for minutes in (0.05, 0.5):
        path = tmp_path / f"busy{minutes}.sr"
        busy_capture(path, minutes)
        assert _compare(path, "sr", monkeypatch) > 5
        assert isinstance(_load(path, "sr").transcript.events, CompactEvents)


@pytest.mark.skipif(not SHARED.is_dir(), reason="the shared captures are not here")
def test_the_shared_captures(monkeypatch: pytest.MonkeyPatch):
    compared = [_compare(path, "sr", monkeypatch) for path in sorted(SHARED.glob("*.sr"))]
    assert any(compared)


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"code": "CC"},
        {"code": "HB"},
        {"meddle": {"1": "3I!"}},
        {"faults": {"0": ["crc-missing"], "3": ["response-too-late"]}},
        {"faults": {"1": ["no-service-request"]}, "code": "M"},
    ],
    ids=str,
)
def test_bus_recordings(tmp_path: Path, kwargs: dict, monkeypatch: pytest.MonkeyPatch):
    path = record(tmp_path / "bus", **kwargs)
    assert _compare(path, "jsonl", monkeypatch) > 5


@pytest.mark.parametrize("fault", [None, "replies-after-retry", "inter-char-gap", "wrong-crc"])
def test_sim_runs(tmp_path: Path, fault, monkeypatch: pytest.MonkeyPatch):
    port = "sim" if fault is None else fault_port((fault, (), "14", ()))
    run_into(tmp_path / "run", port, "sensor")
    given = tmp_path / "run" / "transcript.jsonl"
    assert _compare(given, "jsonl", monkeypatch) > 20
    heard_only = tmp_path / "bus.jsonl"
    write_recording(heard_only, [replace(e, origin=BUS) for e in read_recording(given).events])
    assert _compare(heard_only, "jsonl", monkeypatch) > 20
