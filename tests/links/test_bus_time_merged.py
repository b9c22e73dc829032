"""``bus_time`` merges its spans as it makes them (own spans and forced gaps come in start
order) instead of sorting a list of them all (an hour's capture: 700,000 tuples, 40 MB at
once). The lower bound must be the one sorting gave, to the bit, whatever the events: ties,
overlaps, measurements whose announced waits interleave; and a transcript whose spans cannot
be merged in order (a time that is no number, a break ending before it began) is summed as
before."""

from __future__ import annotations

from operator import attrgetter

from hypothesis import given
from hypothesis import strategies as st

from conformance.links import bus_time as module
from conformance.links.bus_time import bus_time
from conformance.protocol.timing import CHAR_TIME, MARKING_AFTER_BREAK
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1


def sorted_lower_bound(events: list[Event]) -> float:
    """The lower bound as bus_time summed it before: every span in one list, sorted."""
    wire = sorted((e for e in events if e.kind is not EventKind.NOTE), key=attrgetter("start"))
    if not wire:
        return 0.0
    spans: list[tuple[float, float]] = []
    previous = wire[0]
    previous_end = previous.end
    for i, e in enumerate(wire):
        if e.kind is EventKind.BREAK:
            spans.append((e.start, e.end + MARKING_AFTER_BREAK))
        else:
            spans.append((e.start, e.start + CHAR_TIME))
        if i == 0:
            continue
        if e.start > previous_end:
            gap = e.start - previous_end
            spans.append((previous_end, previous_end + module._forced_gap(previous, e, gap)))
        if e.end >= previous_end:
            previous, previous_end = e, e.end
    spans += module._announced_waits(wire)
    return module._sweep(sorted(spans))


#: pieces of traffic: a break, commands, replies (measurements announce waits), whole
#: measurement exchanges (so that waits are common), chatter
TOOL_SAYS = {"0M!", "1C!", "0D0!", "1D0!"}
PIECES = {
    name: [(EventKind.BREAK, TOOL, "")] if name == "break" else [
        (EventKind.CHAR, TOOL if part in TOOL_SAYS else DUT, c)
        for part in name.split(" ")
        for c in (part if part in TOOL_SAYS else part + "\r\n")
    ]
    for name in ("break", "0M!", "1C!", "0D0!", "00011", "100102", "0+1.5", "0",
                 "0M! 00011", "1C! 100102", "0D0! 0+1.5", "1D0! 1+2")
}  # fmt: skip
# steps between events: back to back, overlapping (two talkers), equal starts, pauses
step = st.sampled_from([0.0, CHAR_TIME, CHAR_TIME, -0.004, 0.009, 0.0125, 0.02, 1.5, 0.1])


@st.composite
def traffic(draw) -> list[Event]:
    events: list[Event] = []
    t = 0.0
    for name in draw(st.lists(st.sampled_from(sorted(PIECES)), max_size=24)):
        for kind, origin, c in PIECES[name]:
            t = max(0.0, t + draw(step))
            if kind is EventKind.BREAK:
                length = draw(st.sampled_from([0.0125, 0.013, 0.1]))
                events.append(Event(kind, origin, t, t + length))
            else:
                events.append(Event(kind, origin, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
    if draw(st.booleans()):
        events.append(Event(EventKind.NOTE, TOOL, 0.5, 0.5, text="a note"))
    return draw(st.permutations(events)) if draw(st.booleans()) else events


@given(traffic())
def test_merged_as_made_sums_what_sorting_summed(events: list[Event]):
    assert bus_time(events).lower_bound == sorted_lower_bound(events)


def test_an_announced_wait_counts():
    """A measurement's announced wait, after its reply and before the next break, is in the
    bound (and the merged sum is still the sorted one)."""
    events: list[Event] = []
    t = 0.0
    for kind, origin, c in [*PIECES["break"], *PIECES["0M! 00011"], *PIECES["break"]]:
        if kind is EventKind.BREAK:
            t += 2.0 if events else 0.0  # the second break 2 s after the reply
            events.append(Event(kind, origin, t, t + 0.0125))
            t += 0.0125 + CHAR_TIME
        else:
            events.append(Event(kind, origin, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
            t += CHAR_TIME
    assert module._announced_waits(sorted(events, key=attrgetter("start")))
    assert bus_time(events).lower_bound == sorted_lower_bound(events)
    assert bus_time(events).lower_bound > 1.0  # the 1 s ttt, not only the frames


@given(traffic())
def test_a_malformed_break_takes_the_sorted_way(events: list[Event]):
    odd = [*events, Event(EventKind.BREAK, TOOL, 0.3, 0.3 - 0.05)]  # ends before it began
    assert not module._well_formed(sorted(odd, key=attrgetter("start")))
    assert bus_time(odd).lower_bound == sorted_lower_bound(odd)


def test_a_time_that_is_no_number_takes_the_sorted_way():
    nan = float("nan")
    events = [Event(EventKind.CHAR, TOOL, 0.0, CHAR_TIME, 0x30)]
    events.append(Event(EventKind.CHAR, DUT, nan, nan))
    assert not module._well_formed(events)
    found, expected = bus_time(events).lower_bound, sorted_lower_bound(events)
    assert found == expected or (found != found and expected != expected)
