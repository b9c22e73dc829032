"""A loaded capture's own state no longer grows with its length (issue 22, branch memory25):
once a recording longer than a chunk is loaded and its bus pass done, what it holds in RAM
of its store, its decode's bit-rate errors and the bus pass's numbers (where each window
begins, the transmissions before it, its sides, the windows of each sensor) is at most the
block each column read last, whatever the length; base-s69 held the store's last chunk and
the per-window arrays whole (~17 bytes a window). The figures are the bytes those
structures hold (an array's items; a column's :meth:`resident_nbytes`), exact, so the test
is not at the mercy of the allocator. The chunks are made small (128 events) so that short
captures are written out as an hour's is."""

from __future__ import annotations

from array import array
from pathlib import Path

import pytest

from conformance import event_store
from conformance.event_store import Column
from conformance.offline import sensor_windows
from conformance.offline.heard import bus_of
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.view.windows import stream_window_sides, window_view
from tests.offline.test_bus_pass_compact import _shape
from tests.offline.test_judge_memory import busy_capture

CHUNK, BLOCK = 128, 16


def _bytes(numbers: object) -> int:
    """What ``numbers`` holds in RAM: an array's (or bytearray's) items, a column's resident
    bytes (its chunks not written out and the block it read last)."""
    if isinstance(numbers, Column):
        return numbers.resident_nbytes()
    if isinstance(numbers, array):
        return numbers.itemsize * len(numbers)
    assert isinstance(numbers, bytearray)
    return len(numbers)


def held(path: Path) -> tuple[int, int, object]:
    """The bytes the loaded recording at ``path`` holds of the structures above, how many
    columns they are, and the bus pass."""
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    bus = bus_of(link)
    store, decoded = link.transcript.events, link.decoded
    assert isinstance(store, event_store.CompactEvents) and store.spilled()
    assert decoded is not None
    parts = [
        *store._columns,
        decoded.baud_error_pct,
        bus.codes,
        bus.bounds,
        bus.before,
        bus.chars_before,
        bus.sided,
        *bus.windows_of.values(),
    ]
    return sum(_bytes(p) for p in parts), len(parts), bus


@pytest.fixture
def small_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(event_store, "CHUNK", CHUNK)
    monkeypatch.setattr(event_store, "BLOCK", BLOCK)


@pytest.mark.usefixtures("small_chunks")
def test_what_a_loaded_capture_holds_does_not_grow_with_its_length(tmp_path: Path):
    short, long = tmp_path / "short.sr", tmp_path / "long.sr"
    busy_capture(short, 0.5)
    busy_capture(long, 2.5)
    short_bytes, columns, short_bus = held(short)
    long_bytes, _, long_bus = held(long)
    assert len(long_bus) > 4 * len(short_bus) > 400  # windows: ~250 a minute
    # each column at most the block it read last (8 bytes an item at the widest)
    assert long_bytes <= columns * BLOCK * 8
    # here 196 bytes at both lengths; base-s69 2,659 and 11,155 (its per-window arrays, 17
    # bytes a window, and the store's last chunk)
    assert long_bytes - short_bytes < 1024


@pytest.mark.usefixtures("small_chunks")
def test_the_windows_read_again_from_the_written_out_numbers_as_cut(tmp_path: Path):
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.5)
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    kept = sensor_windows._read_bus(link)  # the bus pass's own arrays, as it made them
    bus = bus_of(link)
    assert isinstance(bus.bounds, Column) and isinstance(bus.sided, Column)
    for mine, theirs in [
        (bus.bounds, kept.bounds),
        (bus.before, kept.before),
        (bus.chars_before, kept.chars_before),
        (bus.sided, kept.sided),
    ]:
        assert len(mine) == len(theirs)
        assert list(mine) == list(theirs)
        assert [mine[i] for i in range(len(mine) - 1, -1, -7)] == list(theirs)[::-7]
        assert list(mine[3:40]) == list(theirs[3:40])
    assert set(bus.windows_of) == set(kept.windows_of)
    for a, windows in bus.windows_of.items():
        assert list(windows) == list(kept.windows_of[a])
    assert list(bus.codes) == list(kept.codes)  # type: ignore[arg-type]
    cut = list(
        stream_window_sides(
            iter(sensor_windows.ordered_plain(link.transcript.events)),
            uncertainty=link.uncertainty,
        )
    )
    assert len(cut) == len(bus)
    for i, (window, sides) in enumerate(cut):
        assert _shape(bus.view(i)) == _shape(window_view(window, sides))
    for address in ("0", "7", None):  # the windows a sensor's pass reads, the same
        assert list(bus.indices(address, lambda: False)) == list(
            kept.indices(address, lambda: False)
        )
    mine_t, theirs_t = bus.transmissions(), kept.transmissions()
    assert len(mine_t) == len(theirs_t)
    assert [t.text for t in mine_t] == [t.text for t in theirs_t]
    assert [t.text for t in mine_t.with_chars()] == [t.text for t in theirs_t.with_chars()]


def test_a_recording_of_one_chunk_keeps_its_arrays(tmp_path: Path):
    """Nothing written out for a short recording (a test's, a matrix row's): no temporary
    file, and its numbers are no longer than a chunk's worth of windows."""
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.05)
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    bus = bus_of(link)
    assert not link.transcript.events.spilled()  # type: ignore[attr-defined]
    assert isinstance(bus.bounds, array) and isinstance(bus.sided, bytearray)
