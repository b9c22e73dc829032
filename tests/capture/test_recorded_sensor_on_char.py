"""The recorded sensor's ``on_char`` with its usual case spelt out (the recording's next
tool event is this character) against ``_match``, which it called for every character
before (issue 22, replay28): the same heard count and offset, and the same divergence or
end of recording, whatever character comes at whatever place."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.replay.sensor import RecordedSensor, ReplayDiverged
from conformance.transcript import EventKind
from tests.capture.test_recorded_sensor_arrays import recordings
from tests.support.capture_digest import traffic


def outcome(sensor: RecordedSensor, hear, wire: int, end: float):
    """What hearing ``wire`` ending at ``end`` did: the state after, or the error."""
    try:
        hear(sensor, wire, end)
    except ReplayDiverged as exc:
        return type(exc).__name__, str(exc)
    return sensor.heard, repr(sensor.offset)


def by_match(sensor: RecordedSensor, wire: int, end: float) -> None:
    sensor._match(EventKind.CHAR, wire, end)


def by_on_char(sensor: RecordedSensor, wire: int, end: float) -> None:
    sensor.on_char(wire, end - 1 / 120, end)


@settings(max_examples=300, deadline=None)
@given(recordings(), st.integers(0, 40), st.integers(0, 255), st.booleans(), st.floats(-1, 3))
def test_on_char_hears_as_match_does(events, place, wire, recorded, end):
    """At any place (past the end too), the recorded character or any other."""
    a, b = RecordedSensor(events), RecordedSensor(events)
    a.heard = b.heard = place
    if recorded and place < len(a.tool):
        wire = a.tool[place].wire
    assert outcome(a, by_on_char, wire, end) == outcome(b, by_match, wire, end)


def test_a_whole_recording_heard_back():
    """Every tool character of a busy recording, heard in turn as the replay hears them
    (breaks through on_break): the same state at every step, and it reaches the end."""
    events = [e for e in traffic(2, seconds=20.0) if e.kind is not EventKind.NOTE]
    a, b = RecordedSensor(events), RecordedSensor(events)
    chars = 0
    for e in a.tool:
        if e.kind is EventKind.CHAR:
            chars += 1
            assert outcome(a, by_on_char, e.wire, e.end + 2e-4) == outcome(
                b, by_match, e.wire, e.end + 2e-4
            )
        else:
            a.on_break(e.start, e.end), b.on_break(e.start, e.end)
    assert chars > 100 and a.heard == b.heard == len(a.tool)
