"""A sensor pass holds no event object for its run (issue 22, memory19): its records hold
their events as positions into the loaded store (``offline.stored_records``), every record
reading as the same pass over the same events held as a list reads it, and the reply-start
fold holds no segment (``judges.wire._StartWhere``). Together they held a sensor's ~35,000
events of an hour's busy capture as objects to the end of its run (5 MB)."""

from __future__ import annotations

import dataclasses
import gc
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest

from conformance import event_store
from conformance.event_store import CompactEvents, StoredEvents
from conformance.judges.wire import ResponseStarts
from conformance.offline.sensor_windows import bus_windows, sensor_records
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.tool_recorder.records import Exchange, Measurement
from conformance.transcript import Event
from conformance.verdicts import Verdict
from conformance.view.runs import Segment
from tests.offline.test_judge_memory import busy_capture
from tests.support.bus_of_sensors import record


def _lists(x: Exchange) -> Iterator[Sequence[Event]]:
    for a in x.attempts:
        yield from (a.command_events, a.reply_events, a.stray_events)
    yield x.heard_late


def _read(x: Exchange) -> list:
    """What a case reads of an exchange: its texts, its events, its tries' timing."""
    return [
        x.text, x.reply_text, x.reply_bytes, x.answered, x.ok, x.start, x.end, list(x.reply_events),
        [(a.reason, a.command_end, a.start, a.reply_text, a.break_event, list(a.stray_events),
          list(a.command_events)) for a in x.attempts],
    ]  # fmt: skip


def _read_measurement(m: Measurement) -> list:
    return [
        _read(m.start), [_read(x) for x in m.data], list(m.waited_events), m.ttt, m.count,
        m.reply_end, m.service_request_end, m.values, m.packets, m.aborted_by,
    ]  # fmt: skip


def _busy(tmp_path: Path) -> Path:
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.5)
    return path


RECORDINGS = {
    "busy": _busy,  # a 1 MHz capture, its store spilled: no measurement, every reply data
    "M": lambda tmp: record(tmp / "bus", code="M", faults={"1": ["no-service-request"]}),
    "CC": lambda tmp: record(tmp / "bus", code="CC", faults={"0": ["values-over-35"]}),
    "HB": lambda tmp: record(tmp / "bus", code="HB", meddle={"1": "3I!"}),
}


@pytest.mark.parametrize("address", ["1", None])
@pytest.mark.parametrize("recording", list(RECORDINGS))
def test_records_hold_positions_and_read_as_listed_ones(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, address: str | None, recording: str
):
    monkeypatch.setattr(event_store, "CHUNK", 512)  # the store's chunks spilled and read back
    monkeypatch.setattr(event_store, "BLOCK", 64)
    path = RECORDINGS[recording](tmp_path)
    link = load_recording(parse_recording(recording_port(str(path), path.suffix[1:])))
    bus = bus_windows(link)
    assert isinstance(bus.events, CompactEvents)
    assert bus.events.spilled() >= (4 if recording == "busy" else 0)
    stored = sensor_records(link, bus, address)
    listed = sensor_records(link, dataclasses.replace(bus, events=list(bus.events)), address)
    assert len(stored.exchanges) == len(listed.exchanges) > 3
    assert len(stored.measurements) == len(listed.measurements) >= (recording != "busy")
    held = [s for x in stored.exchanges for s in _lists(x) if s]
    held += [m.waited_events for m in stored.measurements if m.waited_events]
    assert len(held) >= len(stored.exchanges)  # every command at least
    assert all(isinstance(s, StoredEvents) for s in held)
    assert not any(isinstance(s, StoredEvents) for x in listed.exchanges for s in _lists(x))
    assert [_read(x) for x in stored.exchanges] == [_read(x) for x in listed.exchanges]
    assert [_read_measurement(m) for m in stored.measurements] == [
        _read_measurement(m) for m in listed.measurements
    ]
    for found in ("response_start", "gaps", "bit_rate", "framing"):
        assert getattr(stored, found) == getattr(listed, found)


def _events_alive() -> int:
    gc.collect()
    return sum(1 for o in gc.get_objects() if type(o) is Event)


def test_the_reply_start_fold_holds_no_segment(tmp_path: Path):
    """R-7.0-09/-10's fold over a whole capture read a window at a time keeps each reply's
    observation, whose evidence line is made when asked: it held the reply's segment for
    that (its command's and reply's events as objects, to the end of the sensor's run:
    5 MB of an hour's sensor). Now the few values the line reads; the line the same."""
    path = _busy(tmp_path)
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    bus = bus_windows(link)
    starts = ResponseStarts(link.uncertainty)
    before = _events_alive()
    replies = 0
    for view in bus.read("2", lambda: False):
        segs = [Segment.of(t) for t in view.transmissions if t.text[:1] == "2"]
        replies += sum(1 for s in segs if s.reply)
        starts.add(segs)
        del segs, view
    assert replies > 10
    # the last segment is carried (a reply after the cut may be its late one): its events
    assert _events_alive() - before <= 40
    found = starts.findings()
    assert found[0].verdict == found[1].verdict == Verdict.PASS
    lines = [line for f in found for line in f.evidence]
    assert lines and all(line.startswith("reply to 2D0! at t=") for line in lines)
