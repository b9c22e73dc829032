"""``read_view`` keeps a byte an event for the directions it infers on a recording without
origins (``view.segments._inferred``), where it held every (event, direction) pair and a map
by event (an hour's capture: 25 MB at the peak of its judging). The cut must be the one the
map gave, event for event, whatever the recording: random command and reply texts on one
line, stamps that tie, overlap or come out of (start, end) order, one event object given
twice, events whose origin is known among those that are not."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view.direction import infer_directions
from conformance.view.segments import TranscriptView, _cut, on_tool_link, read_view
from conformance.view.sides import BUS, RECORDER


def by_map(events: list[Event]) -> TranscriptView:
    """The cut as ``read_view`` made it with the map by event (the code before)."""
    ordered = sorted([e for e in events if e.kind is not EventKind.NOTE], key=lambda e: e.start)
    if not any(e.origin == BUS for e in ordered):
        return _cut(ordered, [on_tool_link(e) for e in ordered], 0, [])
    sides = {id(e): d.side for e, d in infer_directions(ordered)}
    undirected = [e for e in ordered if sides.get(id(e), RECORDER) is None]
    kept = [e for e in ordered if sides.get(id(e), RECORDER) is not None]
    mine = [
        sides.get(id(e), RECORDER) == RECORDER if e.origin == BUS else on_tool_link(e) for e in kept
    ]
    return _cut(kept, mine, 0, undirected)


def shape(view: TranscriptView) -> tuple:
    """Every list of the view as the identities of the events it holds, in order."""
    ids = lambda events: [id(e) for e in events]  # noqa: E731
    return (
        [(id(t.break_event), ids(t.chars), ids(t.heard), t.part) for t in view.transmissions],
        ids(view.breaks),
        ids(view.chars),
        ids(view.unanswerable),
        ids(view.undirected),
    )


TEXTS = ["0M!", "0D0!", "0I!", "?!", "0+1.2+3\r\n", "00011\r\n", "0\r\n", "013x\r\n", "0", "!"]
piece = st.tuples(
    st.booleans(),  # a break before it
    st.sampled_from(TEXTS),
    st.sampled_from([0.0, 0.0005, 0.005, 0.009, 0.012, 0.02, 0.1]),  # the pause before it (s)
    st.sampled_from([0.0, 0.0, 0.001, -0.004]),  # between its characters (s): gaps, overlaps
    st.sampled_from([BUS, BUS, BUS, TOOL, DUT]),
)


def recording(pieces, twice: int | None, shuffled: bool) -> list[Event]:
    events: list[Event] = []
    t = 0.0
    for brk, text, pause, gap, origin in pieces:
        t += pause
        if brk:
            events.append(Event(EventKind.BREAK, BUS if origin == BUS else TOOL, t, t + 0.0125))
            t += 0.0125 + 0.009
        for c in text:
            events.append(Event(EventKind.CHAR, origin, t, t + CHAR_TIME, to_wire_7e1(ord(c))))
            t += CHAR_TIME + gap
    if twice is not None and events:
        events.insert(twice % len(events), events[(twice * 7) % len(events)])
    if shuffled and len(events) > 2:  # a longer event first among ties of start
        a = events[1]
        events[1] = Event(a.kind, a.origin, events[0].start, a.end + 0.001, a.wire)
        events[0], events[1] = events[1], events[0]
    return events


@given(st.lists(piece, max_size=14), st.none() | st.integers(0, 200), st.booleans())
def test_the_view_is_the_one_the_map_by_event_gave(pieces, twice, shuffled):
    events = recording(pieces, twice, shuffled)
    assert shape(read_view(events)) == shape(by_map(events))
