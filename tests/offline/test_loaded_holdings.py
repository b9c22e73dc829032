"""``benchmarks/loaded_holdings.py``, what a loaded recording holds and who holds its events
(issue 22), read against what was written: the busy bus's characters and breaks counted
apart, every event's holders counted, each family's bytes those of its objects."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from conformance.capture import export_events
from conformance.transcript import EventKind
from tests.support.paths import benchmark

_load = benchmark


def test_a_loaded_capture_holds_its_events_in_a_store(tmp_path: Path):
    """Since window15: no event of a loaded capture is held as an object, the store holds
    18 bytes an event."""
    events = _load("capture_decode").busy_bus(20.0)
    capture = tmp_path / "busy.sr"
    export_events(events, str(capture), sample_rate=1e6)
    found = _load("loaded_holdings").holdings(str(capture))
    chars = sum(e.kind is EventKind.CHAR for e in events)
    assert found["event_counts"] == {"char": chars, "break": len(events) - chars}
    assert found["events"] == len(events)
    assert found["store_mb"] * 1e6 == 18 * len(events)


def test_families_count_what_a_listed_recording_holds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    """A recording loaded as a list of events (the loader's way where the store refuses an
    event), the families as window12 counted them."""
    from conformance.event_store import CompactEvents
    from conformance.replay.recording import write_recording

    monkeypatch.setattr(CompactEvents, "of", classmethod(lambda cls, events: None))
    events = _load("capture_decode").busy_bus(20.0)
    recording = tmp_path / "busy.jsonl"
    write_recording(recording, events)
    found = _load("loaded_holdings").holdings(str(recording), "jsonl")
    chars = sum(e.kind is EventKind.CHAR for e in events)
    assert found["event_counts"] == {"char": chars, "break": len(events) - chars}
    assert found["events"] == len(events)
    assert sum(found["holders"].values()) == len(events)
    # an event's object (its slots and GC header), each family the sum of its objects'
    one = sys.getsizeof(events[0])
    assert found["event_objects_mb"]["char"] * 1e6 == pytest.approx(chars * one)
    # every start and end, a start equal to the end before it sharing its object
    assert len(events) < found["stamps"] <= 2 * len(events)
    assert found["lists_mb"]["transcript"] * 1e6 >= 8 * len(events)
    # the view's transmissions hold every character, its breaks every recorder's break: no
    # event is held by the transcript's list alone
    assert found["freed_with_list"] == 0
    assert found["transmissions"] == len(events) - chars
