"""Issue 22, round 8: whether the view read a stimulus as the tool recorder did
(``session.same_reading``) compares judged replies by their event objects where the two
records share them, and decodes them only where they do not. The verdict must be that of
comparing the decoded texts and bytes: a reply that differs by one character, or one more
attempt, is another reading; equal events in other objects are the same one."""

from __future__ import annotations

from dataclasses import replace

from conformance.sensor.session import same_reading
from conformance.tool_recorder.records import Attempt, Exchange, Measurement

from ..judges.test_judges import exchange


def _copy(ex: Exchange, reply: list | None = None) -> Exchange:
    """``ex`` with new attempt objects, its reply events ``reply`` (new events by default,
    equal to the old ones)."""
    a = ex.attempts[0]
    events = reply if reply is not None else [replace(e) for e in a.reply_events]
    return Exchange(
        ex.command, ex.text, [Attempt(a.break_event, a.command_events, events, a.reason, a.end)]
    )


def test_shared_events_read_alike() -> None:
    ex = exchange("0I!", "014ACME    SENSOR1230001\r\n", 0.0)
    assert same_reading(ex, _copy(ex, ex.attempts[0].reply_events))


def test_equal_events_in_other_objects_read_alike() -> None:
    ex = exchange("0I!", "014ACME    SENSOR1230001\r\n", 0.0)
    assert same_reading(ex, _copy(ex))


def test_one_character_otherwise_is_another_reading() -> None:
    ex = exchange("0D0!", "0+1.5\r\n", 0.0)
    other = exchange("0D0!", "0+1.6\r\n", 0.0)
    assert not same_reading(ex, _copy(ex, other.attempts[0].reply_events))


def test_one_more_attempt_on_the_same_events_is_another_reading() -> None:
    ex = exchange("0D0!", "0+1.5\r\n", 0.0)
    twice = _copy(ex, ex.attempts[0].reply_events)
    twice.attempts.insert(0, Attempt(None, ex.attempts[0].command_events, [], "no reply", 0.0))
    assert not same_reading(ex, twice)


def test_a_measurement_with_a_d_reply_otherwise_or_fewer_is_another_reading() -> None:
    start = exchange("0M!", "00012\r\n", 0.0)
    d0 = exchange("0D0!", "0+1.5+2\r\n", 1.0)
    made = Measurement(start.command, start, ttt=1, count=2, data=[d0])
    alike = Measurement(start.command, _copy(start), ttt=1, count=2, data=[_copy(d0)])
    assert same_reading(made, alike)
    changed = exchange("0D0!", "0+1.5+3\r\n", 1.0).attempts[0].reply_events
    otherwise = Measurement(start.command, _copy(start), ttt=1, count=2, data=[_copy(d0, changed)])
    assert not same_reading(made, otherwise)
    fewer = Measurement(start.command, _copy(start), ttt=1, count=2, data=[])
    assert not same_reading(made, fewer)
