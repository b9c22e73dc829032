"""Issue 22, matrix round 12: ``case.events_of`` of a list of records joins each record's
events in turn and sorts them once, stably, by start: the same list, element for element
and in the same order among equal starts, as sorting the generator of them did. A case's
evidence (every metadata exchange of a run, every measurement) is what reports cite."""

from __future__ import annotations

from operator import attrgetter

from conformance.case import events_of

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
