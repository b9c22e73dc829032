"""The bus pass's own records of the windows (issue 22's bounded memory,
``offline.sensor_windows.BusWindows``): each event's inferred side in a column whose full
chunks are written out (``conformance.event_store.Column``: an hour's 357,000 sides were a
bytearray of 0.36 MB), and the per-window numbers (where each begins, the transmissions
before it, the windows of each sensor) 4 bytes each, 8 only where the events pass 2**32 - 1. The
windows read again must be the windows the cut gave, spilled or not."""

from __future__ import annotations

from array import array
from pathlib import Path

import pytest

from conformance import event_store
from conformance.offline import sensor_windows
from conformance.offline.sensor_windows import bus_windows, count_typecode, ordered_plain
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.view.windows import stream_window_sides, window_view
from tests.offline.test_judge_memory import busy_capture


def test_the_counts_take_four_bytes_unless_the_events_pass_them():
    assert count_typecode(0) == count_typecode(2**32 - 1) == "I"
    assert array("I", [2**32 - 1])[0] == 2**32 - 1  # the most a window's number can be
    assert count_typecode(2**32) == "q"


def _shape(view) -> list[tuple]:
    """The transmissions (what the recorder sent, what the sensors were heard to send after
    it) and the events no side could be given."""
    sent = [
        (t.text, [e.start for e in t.chars], [e.start for e in t.heard]) for t in view.transmissions
    ]
    return [*sent, [e.start for e in view.undirected]]


def test_the_sides_spill_and_every_window_reads_again_as_cut(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    monkeypatch.setattr(event_store, "CHUNK", 512)
    monkeypatch.setattr(event_store, "BLOCK", 64)
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.5)
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    bus = bus_windows(link)
    assert bus.codes is not None  # one wire: every side inferred
    assert len(bus.codes) == len(bus.events) > 4 * 512
    assert bus.codes.spilled() >= 4
    assert bus.codes.resident_nbytes() <= 512 + 64
    for numbers in (bus.bounds, bus.before, bus.chars_before, *bus.windows_of.values()):
        assert numbers.itemsize == 4
    cut = list(
        stream_window_sides(
            iter(ordered_plain(link.transcript.events)), uncertainty=link.uncertainty
        )
    )
    assert len(cut) == len(bus) > 10
    for i, (window, sides) in enumerate(cut):
        assert _shape(bus.view(i)) == _shape(window_view(window, sides))


@pytest.mark.parametrize("given", [3, None])
def test_windows_whose_sides_were_given_read_again_as_cut(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, given: int | None
):
    """The first ``given`` windows' sides given by their origins (None: every window's), as
    where a recording's events carry their side: no side is kept for them, and the windows
    after them read again with their own sides, not their neighbours'."""
    monkeypatch.setattr(event_store, "CHUNK", 512)
    monkeypatch.setattr(event_store, "BLOCK", 64)
    cut: list = []
    stream = sensor_windows.stream_window_sides

    def some_given(events, uncertainty):
        for i, (window, sides) in enumerate(stream(events, uncertainty=uncertainty)):
            cut.append((window, None if given is None or i < given else sides))
            yield cut[-1]

    monkeypatch.setattr(sensor_windows, "stream_window_sides", some_given)
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.5)
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    bus = bus_windows(link)
    if given is None:
        assert bus.codes is None
    else:
        assert bus.codes is not None and len(bus.codes) == len(bus.events)
        assert not any(bus.codes[: bus.bounds[given]])
    assert len(cut) == len(bus) > 10
    for i, (window, sides) in enumerate(cut):
        assert _shape(bus.view(i)) == _shape(window_view(window, sides))
