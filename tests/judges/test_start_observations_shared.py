"""R-7.0-09/-10 (issue 22, fault-matrix round 10): test_response_start_window asks
:func:`~conformance.judges.wire.starts_after_a_retry` and then
:func:`~conformance.judges.wire.judge_response_start` of one run's segments; both read the
replies' start observations made once per :class:`~conformance.view.runs.Segments` and stamps,
and give what a plain list of the same segments (observed afresh each time) gives."""

from __future__ import annotations

from dataclasses import asdict

import pytest

from conformance.judges import wire
from conformance.judges.timing import StampUncertainty
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view.runs import Segments

CHAR = 8.33e-3


def _chars(origin: str, t: float, text: str) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, t + i * CHAR, t + (i + 1) * CHAR, wire=to_wire_7e1(ord(c)))
        for i, c in enumerate(text)
    ]


def _exchange(t: float, command: str, delay: float | None, reply: str) -> list[Event]:
    """A break, ``command`` and, ``delay`` after its last stop bit, ``reply`` (None: none)."""
    events = [Event(EventKind.BREAK, TOOL, t, t + 0.013)]
    sent = _chars(TOOL, t + 0.03, command)
    events += sent
    if delay is not None:
        events += _chars(DUT, sent[-1].end + delay, reply)
    return events


def _in_time_and_late() -> list[Event]:
    return (
        _exchange(0.0, "0!", 0.010, "0\r\n")
        + _exchange(0.5, "0I!", 0.018, "014TEST\r\n")  # 18 ms: R-7.0-10 FAIL
        + _exchange(1.0, "0M!", 0.0084, "00011\r\n")
    )


def _after_a_retry() -> list[Event]:
    """0! unanswered, then its retry (no break) 60 ms later answered 11 ms after it: the
    reply is in time from the retry and late from the first try."""
    first = [Event(EventKind.BREAK, TOOL, 0.0, 0.013), *_chars(TOOL, 0.03, "0!")]
    retry = _chars(TOOL, first[-1].end + 0.060, "0!")
    return first + retry + _chars(DUT, retry[-1].end + 0.011, "0\r\n")


@pytest.mark.parametrize("events", [_in_time_and_late(), _after_a_retry()])
@pytest.mark.parametrize("stamps", [StampUncertainty(0.0), StampUncertainty(0.5e-3)])
def test_start_judges_on_shared_segments_judge_as_a_plain_list(events, stamps) -> None:
    segs = Segments(wire.segments(events))
    retry = wire.starts_after_a_retry(segs, stamps)
    found = [asdict(f) for f in wire.judge_response_start(segs, stamps)]
    assert retry == wire.starts_after_a_retry(list(segs), stamps)
    assert found == [asdict(f) for f in wire.judge_response_start(list(segs), stamps)]


def test_the_late_reply_fails_and_the_retry_reply_is_set_aside() -> None:
    """What the sharing must keep: the 18 ms reply FAILs R-7.0-10; the reply after a retry
    leaves R-7.0-10 nothing to time, which starts_after_a_retry says."""
    stamps = StampUncertainty(0.0)
    late = Segments(wire.segments(_in_time_and_late()))
    assert not wire.starts_after_a_retry(late, stamps)
    verdicts = {f.requirement: f.verdict.name for f in wire.judge_response_start(late, stamps)}
    assert verdicts == {"R-7.0-09": "PASS", "R-7.0-10": "FAIL"}
    assert wire.starts_after_a_retry(Segments(wire.segments(_after_a_retry())), stamps)


def test_the_case_walks_the_replies_once_per_segments_and_stamps(monkeypatch) -> None:
    """starts_after_a_retry then judge_response_start (the case's order) observe the replies
    once; other stamps, or other segments, observe them again."""
    calls = []
    inner = wire._start_observations

    def counted(*args, **kw):
        calls.append(args[0])
        return inner(*args, **kw)

    monkeypatch.setattr(wire, "_start_observations", counted)
    segs = Segments(wire.segments(_in_time_and_late()))
    stamps = StampUncertainty(0.0)
    wire.starts_after_a_retry(segs, stamps)
    wire.judge_response_start(segs, StampUncertainty(0.0))  # equal stamps, another object
    assert len(calls) == 1
    wire.judge_response_start(segs, StampUncertainty(0.5e-3))
    assert len(calls) == 2
    wire.judge_response_start(Segments(segs), stamps)
    assert len(calls) == 3
