"""The recorded sensor's due replies as slices (``_ReplySpans.run``) against the generator
they replaced (``RecordedSensor._due``, kept for a recording not in order): the same
``(start, wire, duration)`` floats, bit for bit, from every reply, at every count of tool
events heard around its need, at offsets of both signs (issue 22, replay28)."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture.decode import decode_capture
from conformance.capture.export import TOOL_CHANNEL, export_events
from conformance.replay.sensor import LINE_FREE, RecordedSensor
from conformance.transcript import EventKind
from tests.capture.test_recorded_sensor_arrays import recordings
from tests.support.capture_digest import traffic

OFFSETS = (0.0, 1e-5, -3.3e-4, 0.125)


def exact(frames) -> list[tuple[str, int, str]]:
    return [(repr(s), w, repr(d)) for s, w, d in frames]


def by_generator(sensor: RecordedSensor, k: int, heard: int, offset: float) -> list:
    """What frames_ahead offered before: the generator, from a due reply that is not a
    break (frames_ahead's own condition)."""
    return exact(sensor._due(k, heard, offset))


def compare_all(sensor: RecordedSensor) -> int:
    """Every reply, every heard count from its need to two past it, each offset: spans
    and generator agree. How many runs were compared."""
    spans, needs = sensor._spans, sensor._needs
    assert spans is not None
    compared = 0
    for k, need in enumerate(needs):
        if k in sensor._breaks:
            continue
        for heard in (need, need + 1, need + 2):
            for offset in OFFSETS:
                got = exact(spans.run(k, heard, offset))
                assert got == by_generator(sensor, k, heard, offset), (k, heard, offset)
                compared += bool(got)
    return compared


def test_a_decoded_capture_offers_the_same_runs(tmp_path):
    """A capture of a busy, hostile bus, decoded with its TX channel: replies that touch
    (offered at LINE_FREE) and replies that do not, runs cut by the next need."""
    path = tmp_path / "run.sr"
    export_events(traffic(5, seconds=20.0), str(path), "sr", tool_channel=True)
    events = decode_capture(str(path), tx_channel=TOOL_CHANNEL).events
    sensor = RecordedSensor(events)
    assert compare_all(sensor) > 1000
    starts = [s for k in range(len(sensor._needs)) for s, _, _ in sensor._due(k, 10**9, 0.0)]
    assert LINE_FREE in starts and any(math.isfinite(s) for s in starts)


def test_frames_ahead_plays_a_replay_the_same(tmp_path):
    """Two sensors of one capture, one offering by spans, one by the generator, heard the
    same tool events and committing what they offer: the same offers all the way."""
    path = tmp_path / "run.sr"
    export_events(traffic(3, seconds=10.0), str(path), "sr", tool_channel=True)
    events = decode_capture(str(path), tx_channel=TOOL_CHANNEL).events
    fast, slow = RecordedSensor(events), RecordedSensor(events)
    slow._spans = None
    offered = 0
    for tool_event in fast.tool:
        a, b = fast.frames_ahead(), slow.frames_ahead()
        assert (a is None) == (b is None)
        if a is not None and b is not None:
            run = exact(a)
            assert run == exact(b)
            fast.pop_frames(len(run)), slow.pop_frames(len(run))
            offered += len(run)
        for s in (fast, slow):
            while s.next_frame() is not None and s.next_reply in s._breaks:
                s.pop_frame()
            if tool_event.kind is EventKind.CHAR:
                s.on_char(tool_event.wire, tool_event.start + 2e-4, tool_event.end + 2e-4)
            else:
                s.on_break(tool_event.start, tool_event.end)
    assert offered > 500
    assert (fast.heard, fast.next_reply) == (slow.heard, slow.next_reply)


@settings(max_examples=300, deadline=None)
@given(recordings())
def test_any_recording_in_order_offers_the_same_runs(events):
    """Drawn recordings (ties, overlaps, infinite stamps, breaks of both sides): where the
    arrays are taken, spans and generator agree; elsewhere there are no spans."""
    sensor = RecordedSensor(events)
    if sensor._spans is None:
        assert sensor._flags is None
        return
    compare_all(sensor)


@given(st.integers(0, 3))
def test_a_matching_character_is_heard_as_match_hears_it(i):
    """on_char's spelt-out match moves heard and offset as _match does."""
    events = [e for e in traffic(2, seconds=3.0) if e.kind is not EventKind.NOTE]
    a, b = RecordedSensor(events), RecordedSensor(events)
    chars = [e for e in a.tool if e.kind is EventKind.CHAR][: i + 1]
    for e in chars:
        a.heard = b.heard = a.tool.index(e)
        a.on_char(e.wire, e.start, e.end + 1e-3)
        b._match(EventKind.CHAR, e.wire, e.end + 1e-3)
        assert (a.heard, repr(a.offset)) == (b.heard, repr(b.offset))
