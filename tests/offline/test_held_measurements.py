"""A sensor pass's measurements held as rows (issue 22, memory28: ``offline.held_measurements``):
each made again must equal, field for field, the measurement the pass made (today's objects:
the same pass over the recording's events held as a list, where nothing is a row), its start
and data the very exchanges the held exchanges give while it holds them; reading by kind
makes no other; and what the pass holds of a measuring bus's measurements does not grow
with the recording as objects (4 cycles and 20 hold none; their rows a few hundred bytes a
cycle, not the ~1.4 KB an exchange the objects took).

The recording: ``benchmarks/measuring_bus.py``'s cycle (a measurement waiting for its
service request, an immediate one, a CRC one, a concurrent round with one aborted, aHB!
and aHA! read past aD9!, a retried sensor), laid end to end."""

from __future__ import annotations

import gc
import tracemalloc
from pathlib import Path
from types import ModuleType

import pytest

from conformance.offline.held_exchanges import HeldExchanges
from conformance.offline.held_measurements import HeldMeasurements
from conformance.offline.sensor_windows import bus_windows, sensor_records
from conformance.protocol.commands import Kind
from conformance.replay.recording import write_recording
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.tool_recorder.records import Measurement
from conformance.transcript import Transcript
from tests.support.paths import benchmark


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return benchmark("measuring_bus")


def _recording(bench: ModuleType, path: Path, cycles: int) -> Path:
    _, length = bench._cycle()
    write_recording(path, Transcript(bench.measuring_bus(cycles * length + 0.1)))
    return path


def _load(path: Path, *, listed: bool = False):
    link = load_recording(parse_recording(recording_port(str(path), "jsonl")))
    if listed:  # today's records: a list of events holds no position, every record an object
        link.transcript = Transcript(list(link.transcript.events))
    return link


def _fields(m: Measurement) -> tuple:
    """Every field, those the dataclass does not compare too."""
    return (m.command, m.start, m.ttt, m.count, m.reply_end, list(m.waited_events),
            m.service_request_end, m.data, m.values, m.packets, m.binary_value_count,
            m.aborted_by, m.wait_stall)  # fmt: skip


def test_measuring_bus_rows_make_the_pass_measurements(bench: ModuleType, tmp_path: Path):
    path = _recording(bench, tmp_path / "bus.jsonl", 3)
    new_link, old_link = _load(path), _load(path, listed=True)
    addresses = sorted(
        {x.text[:1] for x in sensor_records(new_link, bus_windows(new_link), None).exchanges}
    )
    rows = 0
    for address in [None, *addresses]:
        new = sensor_records(new_link, bus_windows(new_link), address)
        old = sensor_records(old_link, bus_windows(old_link), address)
        held, xs = new.measurements, new.exchanges
        assert isinstance(held, HeldMeasurements) and isinstance(xs, HeldExchanges)
        assert isinstance(old.measurements, HeldMeasurements)
        assert len(old.measurements.kept) == len(old.measurements)  # today's: no row
        assert not held.pending and not old.measurements.pending
        assert len(held) == len(old.measurements)
        made = list(held)
        assert made == list(old.measurements)
        assert [_fields(m) for m in made] == [_fields(m) for m in old.measurements]
        for i, m in enumerate(made):  # the same objects while held, through either list
            assert held[i] is m
            for x in (m.start, *m.data):
                assert any(y is x for y in xs)
        for kinds in ({Kind.MEASURE}, {Kind.CONCURRENT, Kind.HIGH_VOLUME_BINARY}, set(Kind)):
            for whole in (False, True):
                assert held.of_kinds(kinds, whole) == [
                    m for m in old.measurements
                    if m.command.kind in kinds and not (whole and m.aborted_by is not None)
                ]  # fmt: skip
        rows += len(held) - len(held.kept)
        assert not xs.held_for  # every measurement a row: none of its exchanges an object
    assert rows > 30


def _kept(path: Path, address: str) -> tuple[int, int, int]:
    """The traced bytes the pass keeps for ``address``, its measurements and how many of
    them (and of their exchanges) it holds as objects."""
    link = _load(path)
    bus = bus_windows(link)
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    records = sensor_records(link, bus, address)
    gc.collect()
    kept = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    held = records.measurements
    assert isinstance(held, HeldMeasurements) and isinstance(records.exchanges, HeldExchanges)
    objects = len(held.kept) + len(held.pending) + len(records.exchanges.held_for)
    return kept, len(held), objects


def test_measuring_bus_measurements_held_do_not_grow(bench: ModuleType, tmp_path: Path):
    short = _kept(_recording(bench, tmp_path / "4.jsonl", 4), "0")
    long = _kept(_recording(bench, tmp_path / "20.jsonl", 20), "0")
    assert long[1] > 4 * short[1] and short[2] == long[2] == 0
    per = (long[0] - short[0]) / (long[1] - short[1])
    assert per < 1500, per  # bytes a measurement of sensor 0 (its exchanges' rows too)
