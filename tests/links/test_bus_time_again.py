"""``bus_time_again`` reads the events twice as they come, never holding them (a
passive run's bus time with no list of the recording's events, issue 22): its figures must
be :func:`bus_time`'s of the same events as a list, to the bit, whatever they are (notes,
events out of order, malformed ones, none), and it must not make a list of them where they
stand for ``bus_time``'s own list."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from conformance.links import bus_time as module
from conformance.links.bus_time import BusTime, bus_time, bus_time_again
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from tests.links.test_bus_time_merged import traffic
from tests.support.paths import benchmark


def busy_bus(seconds: float) -> list[Event]:
    """The benchmark's busy bus (``benchmarks/capture_decode.busy_bus``)."""
    return benchmark("capture_decode").busy_bus(seconds)


def same(a: BusTime, b: BusTime) -> bool:
    """Equal figures, a NaN equal to a NaN."""
    return all(x == y or (x != x and y != y) for x, y in zip(a.to_json().values(),
                                                              b.to_json().values(), strict=True)) \
        and (a.lower_bound == b.lower_bound or math.isnan(a.lower_bound))  # fmt: skip


class Again:
    """A re-readable source of ``events`` that counts its reads."""

    def __init__(self, events: list[Event]) -> None:
        self.events, self.reads = events, 0

    def __call__(self) -> Iterator[Event]:
        self.reads += 1
        yield from self.events


@given(traffic(), st.booleans())
def test_the_figures_are_bus_time_s(events: list[Event], odd: bool):
    if odd:  # a break ending before it began: the list's way
        events = [*events, Event(EventKind.BREAK, TOOL, 0.3, 0.25)]
    assert same(bus_time_again(Again(events)), bus_time(events))


def test_none_and_notes_only():
    assert bus_time_again(Again([])) == bus_time([]) == BusTime(0.0, 0.0, 0, 0)
    notes = [Event(EventKind.NOTE, TOOL, 0.5, 0.5, text="a note")]
    assert bus_time_again(Again(notes)) == bus_time(notes)


def test_a_time_that_is_no_number_and_an_end_before_a_start():
    nan = float("nan")
    for odd in (Event(EventKind.CHAR, DUT, nan, nan), Event(EventKind.CHAR, DUT, 0.05, 0.04, 0x30)):
        events = [Event(EventKind.CHAR, TOOL, 0.0, CHAR_TIME, 0x30), odd]
        assert same(bus_time_again(Again(events)), bus_time(events))


def test_a_busy_bus_in_three_reads_and_no_list(monkeypatch):
    """Ten minutes of the busy bus: the same figures, three reads, and neither
    ``bus_time`` (the list's way) nor a list of the events made."""
    events = busy_bus(600)
    expected = bus_time(events)
    assert expected.lower_bound > 500 and expected.breaks > 1000
    calls: list[object] = []
    monkeypatch.setattr(module, "bus_time", lambda e: calls.append(e))
    source = Again(events)
    found = bus_time_again(source)
    assert found == expected and source.reads == 2 and not calls


def test_a_sim_run_with_measurements_and_notes():
    """A whole simulated run's transcript (notes among its events, announced waits)."""
    import tempfile

    from conformance.conduct import run_into
    from conformance.replay.recording import read_recording

    with tempfile.TemporaryDirectory() as tmp:
        run_into(Path(tmp), "sim://?faults=wrong-crc", keyword="measurement")
        events = read_recording(Path(tmp) / "transcript.jsonl").events
    assert any(e.kind is EventKind.NOTE for e in events)
    wire = [e for e in events if e.kind is not EventKind.NOTE]
    assert module._announced_waits(wire)
    assert bus_time_again(Again(events)) == bus_time(events)


def test_characters_are_counted_as_frames():
    events = [Event(EventKind.CHAR, TOOL, i * CHAR_TIME, (i + 1) * CHAR_TIME, to_wire_7e1(48))
              for i in range(5)]  # fmt: skip
    assert bus_time_again(Again(events)).frames == 5 == bus_time(events).frames
