"""A run's characters read in one C pass (issue 22, matrix round 4): ``transcript.wire_bytes``
and ``text7``, the framing judge's parity errors and text, and the view's recorder test
by origin, each the same as the per-event reading it stands for, also for events whose wire
is no byte (a made-up event), where they fall back to that reading."""

from __future__ import annotations

import random

import pytest

from conformance.judges import wire as wire_judges
from conformance.judges.timing import StampUncertainty
from conformance.judges.wire import _parity_errors_and_text, judge_framing
from conformance.transcript import (
    DUT,
    TOOL,
    Event,
    EventKind,
    encode_7e1,
    text7,
    wire_bytes,
)
from conformance.verdicts import Verdict
from conformance.view.runs import Segment, segments
from conformance.view.segments import on_tool_link, read_view
from conformance.view.sides import BUS


def _chars(wires: list[int], origin: str = DUT, at: float = 0.0) -> list[Event]:
    step = 1 / 120
    return [
        Event(EventKind.CHAR, origin, at + i * step, at + (i + 1) * step, wire=w)
        for i, w in enumerate(wires)
    ]


WIRES = [
    [],
    list(range(256)),
    [0x30, 0x0D, 0x8A],
    [0x1C1, 0x41],  # a wire past a byte (parity_ok False: its high bits are no parity)
    [-1, 0x41],  # a negative wire: char7 masks it
]


@pytest.mark.parametrize("wires", WIRES)
def test_text7_and_parity_are_the_per_event_reading(wires: list[int]) -> None:
    events = _chars(wires)
    one_by_one = "".join(chr(e.char7) for e in events)
    assert text7(events) == one_by_one
    bad, text = _parity_errors_and_text(events)
    assert text == one_by_one
    assert bad == [e for e in events if not e.parity_ok]


def test_wire_bytes_only_where_every_wire_is_a_byte() -> None:
    assert wire_bytes(_chars([0, 0x7F, 0xFF])) == b"\x00\x7f\xff"
    assert wire_bytes(_chars([0x100])) is None
    assert wire_bytes(_chars([-1])) is None


def test_random_runs_read_alike() -> None:
    rng = random.Random(22)
    for _ in range(300):
        wires = [rng.randrange(-2, 300) if rng.random() < 0.05 else rng.randrange(256)
                 for _ in range(rng.randrange(0, 40))]  # fmt: skip
        events = _chars(wires)
        bad, text = _parity_errors_and_text(events)
        assert text == text7(events) == "".join(chr(e.char7) for e in events)
        assert bad == [e for e in events if not e.parity_ok]


def _run(reply: bytes | list[int]) -> list[Event]:
    command = _chars(list(encode_7e1("0I!")), TOOL)
    answer = _chars(list(reply), DUT, at=command[-1].end + 0.009)
    return command + answer


def test_framing_of_a_reply_with_a_wire_past_a_byte_fails_its_parity() -> None:
    """The framing judge's fallback: a reply character whose wire is no byte is a parity
    error (``Event.parity_ok``), named by its wire, as before the C pass."""
    good = list(encode_7e1("013ACME    SENSOR123456\r\n"))
    findings = {f.requirement: f for f in judge_framing(segments(_run(good)))}
    assert findings["R-4.1-02"].verdict is Verdict.PASS
    odd = good[:3] + [good[3] | 0x100] + good[4:]
    findings = {f.requirement: f for f in judge_framing(segments(_run(odd)))}
    assert findings["R-4.1-02"].verdict is Verdict.FAIL
    assert "first 0x1" in findings["R-4.1-02"].detail
    assert wire_judges._text(segments(_run(odd))[0]) == "013ACME    SENSOR123456\r\n"


def test_the_view_takes_the_tool_links_events_as_the_recorders() -> None:
    """read_view's test of each event's origin (in C) is :func:`on_tool_link`'s; a bus
    origin still goes to the direction inference."""
    events = _run(encode_7e1("0013ACME\r\n"))
    view = read_view(events)
    assert [t.text for t in view.transmissions] == ["0I!"]
    assert [on_tool_link(e) for e in events] == [e.origin == TOOL for e in events]
    assert view.transmissions[0].heard == events[3:]
    bus = [Event(e.kind, BUS, e.start, e.end, wire=e.wire) for e in events]
    assert [t.text for t in read_view(bus).transmissions] == ["0I!"]


def _segment(text: str, starts: list[float], later: list[float]) -> Segment:
    command = _chars(list(encode_7e1(text)), TOOL)
    step = 1 / 120

    def chars(at: list[float]) -> list[Event]:
        return [Event(EventKind.CHAR, DUT, t, t + step, wire=0x30) for t in at]

    return Segment(None, command, reply=chars(starts), later=chars(later), text=text)


def test_spacings_on_one_uncertainty_are_the_pair_by_pair_ones() -> None:
    """R-4.1-01's spacings where every pair has one uncertainty (a virtual clock) are read
    per run in C (``wire._spacings_alike``): the count, the least ``(spacing, command)`` and
    the too-short ones are those of the pair-by-pair pass (a local uncertainty equal to the
    base everywhere takes that pass), with ties, negative zeros and NaN stamps."""
    rng = random.Random(41)
    odd = [0.0, -0.0, float("nan"), 1 / 120, 0.004, float("inf")]
    for _ in range(300):
        segs = []
        for k in range(rng.randrange(1, 5)):
            t, starts, later = 1.0 + k, [], []
            for _ in range(rng.randrange(0, 6)):
                starts.append(float("nan") if rng.random() < 0.05 else t)  # one odd stamp
                t += rng.choice(odd) if rng.random() < 0.2 else rng.choice([1 / 120, 0.0085])
            for _ in range(rng.randrange(0, 3)):
                t += 0.2
                later.append(t)
            segs.append(_segment(rng.choice(["0M!", "0D0!", "1I!"]), starts, later))
        base = rng.choice([0.0, 0.0005])
        alike = wire_judges._spacings(segs, StampUncertainty(base))
        paired = wire_judges._spacings(segs, StampUncertainty(base, lambda a, b, u=base: u))
        assert repr(alike) == repr(paired)
