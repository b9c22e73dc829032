"""Issue 22's fast paths against the straightforward readings they replace: the bulk export
edges against :func:`edges_of`, the bulk sample blocks against filling a block edge by edge,
the decoder's kept frame shapes against reading every frame at its own ticks, a transcript
line against ``json.dumps``, and a written transcript kept as its reading against parsing it.
"""

from __future__ import annotations

import copy
import json
import shutil
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conformance.capture import levels, uart, writers
from conformance.capture.levels import edge_array, edges_of
from conformance.capture.writers import Channel
from conformance.replay import recording
from conformance.replay.recording import read_recording, write_recording
from conformance.replay.sensor import LINE_FREE, RecordedSensor
from conformance.sim.bus import BreakFrame, Frame
from conformance.transcript import (
    DUT,
    TOOL,
    Event,
    EventKind,
    full_event,
    json_line,
    to_wire_7e1,
)
from tests.support.capture_digest import traffic  # noqa: E402
from tests.support.shared_runs import copied_run  # noqa: E402
from tests.support.steady_verdicts import steady  # noqa: E402

RATES = st.sampled_from([1_000.0, 48_000.0, 100_000.0, 625_000.0, 1_000_000.0, 500.0])


@st.composite
def wire_events(draw) -> list[Event]:
    """Characters (some long, some of no or negative length) and breaks that overlap."""
    out = []
    t = draw(st.floats(0.0, 2.0))
    for _ in range(draw(st.integers(0, 40))):
        t += draw(st.floats(-0.02, 0.03))
        if draw(st.booleans()):
            dur = draw(st.sampled_from([10 / 1200, 10 / 1150, 10 / 300, 0.0, 0.06, 0.2, -0.001]))
            wire = draw(st.integers(-3, 300))
            out.append(Event(EventKind.CHAR, draw(st.sampled_from([TOOL, DUT])), t, t + dur, wire))
        else:
            out.append(Event(EventKind.BREAK, TOOL, t, t + draw(st.floats(-0.001, 0.02))))
    if draw(st.booleans()):
        out.sort(key=lambda e: e.start)  # what export gives (unsorted: the slow path)
    return out


@settings(max_examples=150, deadline=None)
@given(wire_events(), RATES, st.floats(0.0, 1.0))
def test_edge_array_is_edges_of(events, rate, t0):
    assert edge_array(events, rate, t0).tolist() == list(edges_of(events, rate, t0))


def test_edge_array_of_a_busy_bus_is_edges_of():
    events = traffic(7, seconds=30.0)
    for rate in (100_000.0, 1_000_000.0):
        assert edge_array(events, rate, 0.03).tolist() == list(edges_of(events, rate, 0.03))


def edge_by_edge(channels: list[tuple[int, list[int]]], total: int, block: int) -> list[bytes]:
    """Sample words as the writer filled them before: a block at a time, edge by edge."""
    blocks = []
    streams = []
    for idle, edges in channels:
        it = iter(edges)
        level, nxt, out = idle, next(it, None), []
        for base in range(0, total, block):
            n = min(block, total - base)
            buf = np.zeros(n, dtype=np.uint8)
            p = base
            while nxt is not None and nxt < base + n:
                if nxt > p:
                    buf[p - base : nxt - base] = level
                    p = nxt
                level ^= 1
                nxt = next(it, None)
            buf[p - base : n] = level
            out.append(buf)
        streams.append(out)
    for parts in zip(*streams, strict=True):
        word = parts[0].copy()
        for bit, b in enumerate(parts[1:], 1):
            word |= b << bit
        blocks.append(word.tobytes())
    return blocks


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    st.lists(
        st.tuples(st.integers(0, 1), st.lists(st.integers(-5, 400), max_size=30)),
        min_size=1,
        max_size=3,
    ),
    st.integers(0, 350),
)
def test_sample_words_are_the_edge_by_edge_fill(monkeypatch, channels, total):
    """Any edge list, even one going back or past the end, fills the same samples."""
    monkeypatch.setattr(writers, "BLOCK_SAMPLES", 64)
    got = [
        w.tobytes()
        for w in writers._words(
            [Channel(f"c{i}", idle, e) for i, (idle, e) in enumerate(channels)], total
        )
    ]
    assert got == edge_by_edge(channels, total, 64)


def decoded(edges: list[int], rate: float, **kw) -> list:
    chunks = [edges[i : i + 37] for i in range(0, len(edges), 37)]
    return list(uart.decode(chunks, initial_level=1, tick_rate=rate, end_tick=lambda: None, **kw))


@st.composite
def jittered_frames(draw) -> tuple[list[int], float]:
    """Edges of 7E1 frames at a drawn bit rate, jittered and sometimes glitched."""
    rate = draw(st.sampled_from([9_600.0, 48_000.0, 100_000.0, 1_000_000.0]))
    start = draw(st.sampled_from([0, 10**6, 2**39 - 10**5, 2**41]))  # shapes off past 2**39
    bit = rate / 1200 * draw(st.sampled_from([1.0, 0.96, 1.04, 1.1]))
    edges: list[int] = []
    t = start + draw(st.integers(1, 50))
    for c in draw(st.text("0123456789+-.!aDM\r\n", min_size=1, max_size=25)):
        wire = to_wire_7e1(ord(c)) if draw(st.integers(0, 9)) else draw(st.integers(0, 255))
        levels_ = [0] + [(wire >> i) & 1 for i in range(8)] + [1]
        prev = 1
        for k, lvl in enumerate(levels_):
            if lvl != prev:
                edges.append(int(t + k * bit) + draw(st.integers(-1, 1)))
                prev = lvl
        if draw(st.integers(0, 12)) == 0:
            g = int(t + draw(st.floats(0.3, 9.0)) * bit)
            edges += [g, g + 1]
        t += 10 * bit + draw(st.sampled_from([0, 0, 3, int(bit), int(20 * bit)]))
    edges = sorted(set(edges))
    return edges, rate


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(jittered_frames())
def test_kept_frame_shapes_read_as_every_frame_read_alone(monkeypatch, frames):
    edges, rate = frames
    kept = decoded(edges, rate)
    monkeypatch.setattr(uart, "_EXACT_BELOW", 0)  # no shape kept: every frame at its ticks
    assert kept == decoded(edges, rate)


def test_an_edge_on_a_bit_centre_is_read_at_its_own_ticks(monkeypatch):
    """Bit centres of 1200 baud at 2.4 kHz fall on whole ticks: such a shape is never kept
    (a start far out could round its centre to either side), and reads as read alone."""
    calls = []
    real = uart._read_frame
    monkeypatch.setattr(uart, "_read_frame", lambda *a: calls.append(a[0]) or real(*a))
    edges = []
    for n in range(4):
        s = 2**38 + n * 30
        edges += [s, s + 1, s + 3, s + 4]  # 0x55-like: edges half a bit off the centres
    got = decoded(edges, 2400.0)
    assert [d.kind for d in got] == ["char"] * 4
    assert 2**38 in calls  # read at its own ticks, not as a kept shape
    monkeypatch.setattr(uart, "_EXACT_BELOW", 0)
    assert got == decoded(edges, 2400.0)


def test_frame_shapes_stay_bounded(monkeypatch):
    monkeypatch.setattr(uart, "FRAME_SHAPES", 3)
    monkeypatch.setattr(uart, "_KEPT", {})  # none kept by an earlier decode in this process
    sizes = []
    real = uart._shape_reading
    monkeypatch.setattr(uart, "_shape_reading", lambda *a: sizes.append(1) or real(*a))
    edges, rate = [], 100_000.0
    t = 100
    for k in range(40):  # a sender drifting: a new shape nearly every frame
        bit = 83.3 + k * 0.05
        edges += [t, int(t + bit), int(t + 2 * bit), int(t + 9 * bit)]
        t += int(12 * bit)
    kept = decoded(edges, rate)
    monkeypatch.setattr(uart, "_EXACT_BELOW", 0)
    assert kept == decoded(edges, rate)
    assert len(sizes) > 3


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(jittered_frames(), jittered_frames())
def test_shapes_kept_by_earlier_decodes_read_as_every_frame_read_alone(monkeypatch, one, two):
    """The process keeps each line's shapes across decodes (a matrix worker decodes the same
    line hundreds of times): a decode that finds another's shapes, of its own line or of
    another line, reads as it would alone."""
    monkeypatch.setattr(uart, "_KEPT", {})
    got = [decoded(edges, rate) for edges, rate in (one, two, one, two)]
    assert got[2] == got[0] and got[3] == got[1]
    assert len(uart._KEPT) == len({one[1], two[1]})  # one line per tick rate, kept
    monkeypatch.setattr(uart, "_EXACT_BELOW", 0)  # no shape kept: every frame at its ticks
    assert got[:2] == [decoded(edges, rate) for edges, rate in (one, two)]


def test_kept_lines_stay_bounded(monkeypatch):
    monkeypatch.setattr(uart, "_KEPT", {})
    monkeypatch.setattr(uart, "KEPT_LINES", 2)
    edges = [100, 183, 266, 933]
    for rate in (100_000.0, 48_000.0, 9_600.0, 100_000.0):
        decoded(edges, rate)
    assert [key[0] for key in uart._KEPT] == [9_600.0 / 1200, 100_000.0 / 1200]


TEXTS = st.text(st.characters(), max_size=12)
FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-5, 5), st.just(-0.0)
)
#: every field of an Event, in order, with the awkward values a line or a copy must keep
EVENT_FIELDS = (
    st.sampled_from(list(EventKind)),
    st.sampled_from([TOOL, DUT, "bus", 'é\n"x']),
    FLOATS,
    FLOATS,
    st.one_of(st.integers(-3, 1 << 70), st.booleans()),
    TEXTS,
    FLOATS,
    st.one_of(st.none(), FLOATS),
)


@settings(max_examples=400, deadline=None)
@given(*EVENT_FIELDS)
def test_json_line_is_json_dumps(kind, origin, start, end, wire, text, unc, du):
    e = Event(kind, origin, start, end, wire, text, unc, du)
    assert json_line(e) == json.dumps(e.to_json()) + "\n"


@settings(max_examples=200, deadline=None)
@given(*EVENT_FIELDS)
def test_full_event_is_the_event_its_constructor_makes(kind, origin, start, end, wire, text, u, du):
    """transcript.full_event (the capture decoder's and TX merge's fast way to make an
    event) sets every field as the frozen constructor does: equal, same hash, same types."""
    fields = (kind, origin, start, end, wire, text, u, du)
    fast, made = full_event(*fields), Event(*fields)
    assert fast == made and hash(fast) == hash(made)
    for name in Event.__slots__:
        assert getattr(fast, name) is getattr(made, name)


def test_a_written_transcript_is_its_own_reading(tmp_path, monkeypatch):
    events = [
        Event(EventKind.NOTE, TOOL, 0.0, 0.0, text='run-options {"role": "sensor"}'),
        *traffic(3, seconds=2.0),
        Event(EventKind.CHAR, DUT, 3.0, 3.1, 65, "", 1e-5, 2e-6),
    ]
    path = tmp_path / "transcript.jsonl"
    write_recording(path, events)
    parsed = []
    real = recording.read_transcript_jsonl
    monkeypatch.setattr(recording, "read_transcript_jsonl", lambda p: parsed.append(p) or real(p))
    kept = read_recording(path).events
    assert parsed == []  # nothing parsed: what was written is the reading
    recording._READ.clear()
    fresh = read_recording(path).events
    assert parsed == [str(path)]
    assert kept == fresh
    assert [tuple(map(type, (e.start, e.end, e.wire, e.uncertainty))) for e in kept] == [
        tuple(map(type, (e.start, e.end, e.wire, e.uncertainty))) for e in fresh
    ]


def test_a_transcript_that_reads_back_otherwise_is_parsed(tmp_path):
    """An int time is written as an int and read back as a float: never kept as written."""
    path = tmp_path / "transcript.jsonl"
    write_recording(path, [Event(EventKind.CHAR, DUT, 1, 2, 65)])
    (got,) = read_recording(path).events
    assert type(got.start) is float and got.start == 1.0


def test_a_rewritten_transcript_is_read_again(tmp_path):
    path = tmp_path / "transcript.jsonl"
    write_recording(path, [Event(EventKind.CHAR, DUT, 1.0, 2.0, 65)])
    assert read_recording(path).events[0].wire == 65
    path.write_text(json.dumps(Event(EventKind.CHAR, DUT, 1.0, 2.0, 66, "x").to_json()) + "\n")
    assert read_recording(path).events[0].wire == 66


@pytest.mark.parametrize("rate", [100_000.0, 1_000_000.0])
def test_the_bulk_export_is_taken_for_a_busy_bus(monkeypatch, rate):
    """The slow path is for what the bulk union could order differently, not for traffic."""
    monkeypatch.setattr(levels, "edges_of", None)
    assert edge_array(traffic(9, seconds=5.0), rate, 0.0).size > 1000


def offer_worked_out(sensor: RecordedSensor) -> Frame | None:
    """The frame a :class:`RecordedSensor` offers, worked out from its state as the replay
    first did at every step: the reply's question heard, then whether it touches the
    recorded event that ended last before it (the tool's last matched one or the previous
    reply, the later-ending; the tool's on a tie)."""
    k = sensor.next_reply
    if k >= len(sensor.replies) or sensor._needs[k] > sensor.heard:
        return None
    reply = sensor.replies[k]
    found = [sensor.tool[sensor.heard - 1]] if sensor.heard else []
    if k:
        found.append(sensor.replies[k - 1])
    found = [e for e in found if e.start < reply.start]
    before = max(found, key=lambda e: e.end, default=None)
    start = reply.start + sensor.offset
    if before is not None and abs(reply.start - before.end) <= (
        reply.uncertainty + before.uncertainty
    ):
        start = LINE_FREE
    length = reply.end - reply.start
    if reply.kind is EventKind.BREAK:  # the sensor's break, played as spacing that long
        return BreakFrame(start, 0, length, 0.0 if start == LINE_FREE else start + length)
    return Frame(start, reply.wire, length)


@pytest.mark.parametrize(("seed", "uncertainty"), [(3, 0.0), (7, 0.0), (7, 1e-5), (8, 2e-3)])
def test_the_replayed_sensor_offers_what_it_would_work_out_anew(seed, uncertainty):
    """:class:`RecordedSensor` works out once per reply whether it goes back to back, and
    keeps the frame it offered until a tool event is matched or a reply popped (the bus asks
    at every step between): at every point of a replay, with the tool late or early against
    the recording, its offer is the one worked out anew from its state."""
    events = [replace(e, uncertainty=uncertainty) for e in traffic(seed, seconds=3.0)]
    sensor = RecordedSensor(events)
    tool = sorted((e for e in events if e.origin == TOOL), key=lambda e: (e.start, e.end))
    popped, free, past = 0, 0, 0
    for n, e in enumerate([*tool, None]):
        # the replies due, popped now or (every third turn) left until the tool went on
        while (n % 3 or e is None) and (offer := sensor.next_frame()) is not None:
            assert offer == offer_worked_out(sensor)
            free += offer.start == LINE_FREE
            past += sensor.heard > sensor._needs[sensor.next_reply]
            assert sensor.pop_frame() == offer
            assert sensor.next_frame() == offer_worked_out(sensor)
            popped += 1
        if e is None:
            break
        assert sensor.next_frame() == offer_worked_out(sensor)
        shift = (n % 7 - 3) * 1e-4  # the tool now late, now early
        if e.kind is EventKind.BREAK:
            sensor.on_break(e.start + shift, e.end + shift)
        else:
            sensor.on_char(e.wire, e.start + shift, e.end + shift)
    assert popped == len(sensor.replies)
    assert popped > 20 and 0 < free < popped and past > 0  # both cases, both ways


def test_on_a_tie_the_tools_event_is_the_one_before_a_reply():
    """The tool's last event and the previous reply end together: the tool's (here the one
    with no uncertainty) decides whether the next reply touches it."""
    sensor = RecordedSensor(
        [
            Event(EventKind.CHAR, TOOL, 0.0, 1.0, 0x30),
            Event(EventKind.CHAR, DUT, 0.5, 1.0, 0x31, "", 0.3),
            Event(EventKind.CHAR, DUT, 1.2, 2.0, 0x32),
        ]
    )
    sensor.on_char(0x30, 0.0, 1.0)
    sensor.pop_frame()
    assert sensor.next_frame() == offer_worked_out(sensor) == Frame(1.2, 0x32, 0.8)


def offered_one_by_one(sensor: RecordedSensor) -> list[tuple[float, int, float]]:
    """What :meth:`RecordedSensor.next_frame` offers frame after frame, each popped, while
    the tool sends nothing, up to the sensor's next break (played frame by frame: the bus
    commits a ``BreakFrame`` as spacing): the straightforward reading of ``frames_ahead``.
    Works on a copy (the sensor itself is left as it was)."""
    twin = copy.copy(sensor)
    offered = []
    while (frame := twin.next_frame()) is not None and type(frame) is not BreakFrame:
        offered.append((frame.start, frame.wire, frame.duration))
        twin.pop_frame()
    return offered


@pytest.mark.parametrize(("seed", "uncertainty"), [(3, 0.0), (7, 1e-5), (8, 2e-3)])
def test_the_replayed_sensors_planned_replies_are_its_offers_in_turn(seed, uncertainty):
    """:meth:`RecordedSensor.frames_ahead` (the sim bus commits them in one run) at every
    point of a replay, with the tool late or early against the recording and some replies
    left pending, is what ``next_frame``/``pop_frame`` would offer one by one; and
    ``pop_frames(n)`` leaves the sensor where n ``pop_frame`` calls would."""
    events = [replace(e, uncertainty=uncertainty) for e in traffic(seed, seconds=3.0)]
    sensor = RecordedSensor(events)
    tool = sorted((e for e in events if e.origin == TOOL), key=lambda e: (e.start, e.end))
    # each reply's question: the tool's events that start before it, counted one by one
    assert sensor._needs == [sum(t.start < r.start for t in tool) for r in sensor.replies]
    planned = popped = 0
    for n, e in enumerate([*tool, None]):
        while True:  # once, or at the end until nothing is due
            if n % 3 or e is None:
                while type(sensor.next_frame()) is BreakFrame:  # the bus commits it alone
                    sensor.pop_frame()
                    popped += 1
            expected = offered_one_by_one(sensor)
            ahead = sensor.frames_ahead()
            assert (ahead is None) == (not expected)
            if ahead is not None and (n % 3 or e is None):
                got = list(ahead)
                assert got == expected
                take = len(got) if n % 2 or e is None else (len(got) + 1) // 2
                twin = copy.copy(sensor)
                for _ in range(take):
                    twin.pop_frame()
                sensor.pop_frames(take)
                assert (sensor.next_reply, sensor.next_frame()) == (
                    twin.next_reply,
                    twin.next_frame(),
                )
                planned += take
                popped += take
            if e is not None or ahead is None:
                break
        if e is None:
            break
        shift = (n % 7 - 3) * 1e-4  # the tool now late, now early
        if e.kind is EventKind.BREAK:
            sensor.on_break(e.start + shift, e.end + shift)
        else:
            sensor.on_char(e.wire, e.start + shift, e.end + shift)
    assert popped == len(sensor.replies) and planned > 20


@pytest.mark.slow
@pytest.mark.parametrize("fault", ["response-too-early", "wrong-crc", "late-service-request"])
def test_a_capture_replayed_in_planned_runs_is_the_replay_frame_by_frame(
    tmp_path, tmp_path_factory, monkeypatch, fault
):
    """A fault run's capture (exported with the tool's TX, decoded as ``judge`` does) replayed
    with the recorded sensor's replies committed in runs gives the transcript and the
    verdicts of the replay frame by frame: event for event, finding for finding."""
    from conformance.capture.export import export_events
    from conformance.conduct import conduct
    from conformance.offline.judge import plan
    from conformance.sim.bus import SimBus

    # the main command's run of the fault, made once a session (wrong-crc and
    # response-too-early are judged in other modules too: tests/support/shared_runs.py)
    copied_run(tmp_path_factory, tmp_path / "live", f"sim://?faults={fault}")
    events = read_recording(tmp_path / "live").events
    notes = [e for e in events if e.kind is EventKind.NOTE]
    export_events(events, str(tmp_path / "run.sr"), "sr", tool_channel=True, notes=notes)
    replays, in_runs = [], []
    pop_frames = RecordedSensor.pop_frames
    monkeypatch.setattr(
        RecordedSensor, "pop_frames", lambda self, n: in_runs.append(n) or pop_frames(self, n)
    )
    for planned in (True, False):
        if not planned:
            assert sum(in_runs) > 100  # the runs were taken: the comparison compares something
            monkeypatch.setattr(SimBus, "planned_run", lambda self: None)
        again = tmp_path / "capture"  # the same folder, named in the run's notes
        shutil.rmtree(again, ignore_errors=True)
        found = plan([str(tmp_path / "run.sr"), "--report-dir", str(again)])
        result = conduct(replace(found.replay, report_dir=str(again)), html=False, rootdir=again)
        replays.append((list(result.run.link.transcript.events), steady(result.document)))
    assert replays[0][0] and replays[0] == replays[1]
