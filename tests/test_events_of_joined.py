"""Issue 22, matrix round 12: ``case.events_of`` of a list of records joins each record's
events in turn and sorts them once, stably, by start: the same list, element for element
and in the same order among equal starts, as sorting the generator of them did. A case's
evidence (every metadata exchange of a run, every measurement) is what reports cite."""

from __future__ import annotations

import itertools
import math
from operator import attrgetter

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.case import events_of
from conformance.protocol.commands import parse_command
from conformance.tool_recorder.records import Attempt, Exchange, Measurement
from conformance.transcript import DUT, Event, EventKind

from .judges.test_judges import exchange, measurement


def _plain(record):  # the joining it replaced, as it was
    if isinstance(record, (list, tuple)) and not all(hasattr(r, "kind") for r in record):
        return sorted((e for r in record for e in events_of(r)), key=attrgetter("start"))
    return events_of(record)


def test_records_out_of_order_and_overlapping_join_as_before() -> None:
    a = exchange("0I!", "013ACME  SENSOR 1.0\r\n", 0.0)
    b = exchange("0D0!", "0+1.5+2\r\n", 0.05)  # starts inside a's reply
    c = exchange("0M!", "00012\r\n", 0.0)  # the same starts as a: ties
    m = measurement("00012\r\n", 0.3, [("0D0!", "0+1+2\r\n")])
    for records in ([a, b, c], [c, a, b], [b, m, a, c], [m], [a, [b, c]], [], [a, (m,)]):
        got, want = events_of(records), _plain(records)
        assert len(got) == len(want)
        assert all(g is w for g, w in zip(got, want, strict=True))


def test_a_list_of_events_is_copied_as_it_is() -> None:
    events = exchange("0!", "0\r\n", 1.0).attempts[0].reply_events[::-1]
    got = events_of(events)
    assert got == events and got is not events


# -- matrix21: joined unsorted and sorted once, the parts' sorts left out -----------------------


def _as_before(record):  # events_of until matrix21, as it was: each part sorted, then the whole
    if record is None:
        return []
    if isinstance(record, Event):
        return [record]
    if isinstance(record, Exchange):
        found = []
        for a in record.attempts:
            found += a.stray_events
            if a.break_event is not None:
                found.append(a.break_event)
            found += a.command_events + a.reply_events
        return sorted(found, key=attrgetter("start"))
    if isinstance(record, Measurement):
        found = _as_before(record.start) + list(record.waited_events)
        for ex in record.data:
            found += _as_before(ex)
        return sorted(found, key=attrgetter("start"))
    if all(isinstance(r, Event) for r in record):
        return list(record)
    found = []
    for r in record:
        found += _as_before(r)
    found.sort(key=attrgetter("start"))
    return found


# few starts, so that ties are many; NaN and the infinities now and then
STARTS = st.sampled_from([0.0, 0.1, 0.1, 0.2, 0.3, -0.0, math.inf, -math.inf, math.nan])
_n = itertools.count()


@st.composite
def _events(draw, most: int = 4) -> list[Event]:
    starts = draw(st.lists(STARTS, max_size=most))
    return [Event(EventKind.CHAR, DUT, s, s + 0.008, next(_n) % 256) for s in starts]


@st.composite
def _exchange(draw) -> Exchange:
    attempts = [
        Attempt(
            draw(st.none() | _events(1).filter(bool).map(lambda e: e[0])),
            draw(_events()),
            draw(_events()),
            "ok",
            1.0,
            stray_events=draw(_events(2)),
        )  # fmt: skip
        for _ in range(draw(st.integers(1, 3)))
    ]
    return Exchange(parse_command("0M!"), "0M!", attempts)


@st.composite
def _measurement(draw) -> Measurement:
    start = draw(_exchange())
    m = Measurement(start.command, start, ttt=1, count=1)
    m.waited_events = draw(_events())
    m.data = draw(st.lists(_exchange(), max_size=3))
    return m


_record = st.deferred(
    lambda: (
        _exchange()
        | _measurement()
        | _events().map(lambda e: e[0] if e else None)
        | st.lists(_record, max_size=4)
        | st.lists(_record, max_size=3).map(tuple)
        | _events()
    )
)


@settings(max_examples=200, deadline=None)
@given(_record)
def test_sorted_once_is_the_parts_sorted_in_turn(record) -> None:
    """Element for element (the same objects, equal starts in the same order) what sorting
    each part and then the whole gave; with a NaN start among them too (then sorted so)."""
    got, want = events_of(record), _as_before(record)
    assert len(got) == len(want)
    assert all(g is w for g, w in zip(got, want, strict=True))
