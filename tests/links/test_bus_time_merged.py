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


def _spans_merged(wire: list[Event]) -> list[tuple[float, float]]:
    """What bus_time merged before :func:`~bus_time._spans_in_order`: heapq.merge of the
    three streams."""
    from heapq import merge
    from operator import itemgetter

    waits = sorted(module._announced_waits(wire))
    return list(merge(module._own_spans(wire), module._gaps(wire), waits, key=itemgetter(0)))


@given(traffic(), st.lists(st.sampled_from([0.0, 0.001, CHAR_TIME]), max_size=30))
def test_the_spans_in_one_loop_are_the_merged_ones_in_their_order(events, shorter):
    """The one-loop spans are heapq.merge's, element for element and in its order (ties
    included), also where events end where they start or overlap the next; where one ends
    before it starts the merge is kept, and either way the bound is the sorted one."""
    events = [
        Event(e.kind, e.origin, e.start, e.start + shorter[i], e.wire) if i < len(shorter) else e
        for i, e in enumerate(events)
    ]
    wire = sorted((e for e in events if e.kind is not EventKind.NOTE), key=attrgetter("start"))
    if wire and module._well_formed(wire) and module._ends_after_starts(wire):
        waits = sorted(module._announced_waits(wire))
        assert list(module._spans_in_order(wire, waits)) == _spans_merged(wire)
    assert bus_time(events).lower_bound == sorted_lower_bound(events)


def test_an_event_ending_before_it_starts_is_merged_as_before():
    events = [
        Event(EventKind.CHAR, TOOL, 0.0, CHAR_TIME, to_wire_7e1(ord("0"))),
        Event(EventKind.CHAR, DUT, 0.05, 0.04, to_wire_7e1(ord("0"))),  # ends before it began
        Event(EventKind.CHAR, DUT, 0.045, 0.06, to_wire_7e1(ord("1"))),
    ]
    wire = sorted(events, key=attrgetter("start"))
    assert module._well_formed(wire) and not module._ends_after_starts(wire)
    assert bus_time(events).lower_bound == sorted_lower_bound(events)


def test_a_simulated_run_s_spans_are_the_merged_ones() -> None:
    """A whole simulated run (measurements, waits, breaks, retries) in one loop and merged."""
    import tempfile
    from pathlib import Path

    from conformance.conduct import run_into
    from conformance.replay.recording import read_recording
    from conformance.transcript import in_start_order

    with tempfile.TemporaryDirectory() as tmp:
        run_into(Path(tmp), "sim://?faults=wrong-crc", keyword="measurement or crc")
        events = read_recording(Path(tmp) / "transcript.jsonl").events
    wire = in_start_order(events)
    assert len(wire) > 1000 and module._ends_after_starts(wire)
    waits = sorted(module._announced_waits(wire))
    assert waits and list(module._spans_in_order(wire, waits)) == _spans_merged(wire)
