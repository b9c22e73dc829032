"""The UART decoder (``conformance.capture.uart``) on edges written here by hand: a 7E1 frame
reads as its character, a parity error and a framing error are flagged, a 4 % fast sender is
measured as such, and a 13 ms spacing is a break (R-4.1-01, R-7.0-01/-04 rest on these)."""

from __future__ import annotations

import pytest

from conformance.capture import uart
from conformance.transcript import EventKind, to_wire_7e1

RATE = 1_000_000.0  # ticks per second: a 1 MHz logic analyser
BIT = RATE / 1200  # ticks per bit at 1200 baud
START = 20 * BIT  # the first frame's start: after enough marking to be told a start bit


def frame_edges(start: float, wire: int, bit: float = BIT, *, stop: int = 1) -> list[int]:
    """The edges of one frame: start bit, 8 bits of ``wire`` LSB first, the stop bit."""
    levels = [0] + [(wire >> i) & 1 for i in range(8)] + [stop]
    edges, prev = [], 1
    for k, level in enumerate(levels):
        if level != prev:
            edges.append(round(start + k * bit))
            prev = level
    if prev == 0:  # a spacing stop bit: the line goes back to marking after it
        edges.append(round(start + 10 * bit))
    return edges


def decode(edges: list[int], end: int, level: int = 1) -> list[uart.Decoded]:
    """``level``: the line's level at the capture's first sample."""
    return list(uart.decode([edges], initial_level=level, tick_rate=RATE, end_tick=lambda: end))


def chars(found: list[uart.Decoded]) -> list[uart.Decoded]:
    return [d for d in found if d.event is not None and d.event.kind is EventKind.CHAR]


def test_a_frame_reads_as_its_character_at_its_stamps():
    edges = frame_edges(START, to_wire_7e1(ord("0"))) + frame_edges(START + 10 * BIT, ord("!"))
    found = chars(decode(edges, round(START + 40 * BIT)))
    assert [d.event.wire for d in found] == [to_wire_7e1(ord("0")), to_wire_7e1(ord("!"))]
    assert found[0].start == pytest.approx(START / RATE, abs=2 / RATE)
    assert found[0].end == pytest.approx((START + 10 * BIT) / RATE, abs=2 / RATE)
    assert not any(d.parity_error or d.framing_error for d in found)


def test_a_parity_error_and_a_spacing_stop_bit_are_flagged():
    wrong_parity = to_wire_7e1(ord("1")) ^ 0x80
    edges = frame_edges(START, wrong_parity) + frame_edges(START + 20 * BIT, ord("2"), stop=0)
    found = chars(decode(edges, round(START + 60 * BIT)))
    assert found[0].parity_error and not found[0].framing_error
    assert found[1].framing_error


@pytest.mark.parametrize("off", [0.96, 1.04])
def test_a_sender_4_percent_off_is_measured_as_such(off):
    """R-4.1-01 is judged from this figure: 1200 baud within 2 % (decision A14)."""
    bit = BIT * off
    edges = frame_edges(START, to_wire_7e1(ord("U")), bit)  # 0x55: an edge at every bit
    (found,) = chars(decode(edges, round(START + 40 * bit)))
    assert found.baud_error_pct == pytest.approx((1 / off - 1) * 100, abs=0.5)


def test_a_13_ms_spacing_is_a_break_and_a_short_one_is_not():
    long_start, short_start = 1000, round(START + 30e-3 * RATE)
    edges = [long_start, long_start + round(13e-3 * RATE)]
    edges += [short_start, short_start + round(5e-3 * RATE)]
    found = decode(edges, round(short_start + 50e-3 * RATE))
    breaks = [d for d in found if d.event is not None and d.event.kind is EventKind.BREAK]
    assert len(breaks) == 1
    assert breaks[0].event.end - breaks[0].event.start == pytest.approx(13e-3, abs=1e-5)


def test_a_capture_begun_inside_a_reply_reads_from_the_first_start_bit_it_can_tell():
    """Issue 23: a capture started inside a reply decoded its rest as garbage characters.
    Frames before a marking run long enough to prove a start bit are dropped as partial."""
    text = "0+1.25+3\r\n"
    edges: list[int] = []
    t = -4.5 * BIT  # the first frame began before the capture: its start bit is not in it
    for c in text:
        edges += frame_edges(t, to_wire_7e1(ord(c)))
        t += 10 * BIT
    before = [e for e in edges if e <= 0]
    edges = [e for e in edges if e > 0]
    level = 1 - len(before) % 2  # the line's level at the first sample
    t += 20 * BIT  # the line marks, then a command the capture sees whole
    for c in "0D0!":
        edges += frame_edges(t, to_wire_7e1(ord(c)))
        t += 10 * BIT
    found = decode(sorted(set(edges)), round(t + 30 * BIT), level)
    got = "".join(chr(d.event.wire & 0x7F) for d in chars(found))
    assert got == "0D0!"
    assert sum(d.kind == "partial" for d in found) >= 1


def test_a_capture_ended_inside_a_character_drops_it_rather_than_invent_one():
    """Issue 23: a capture that ended inside a spacing bit turned the unfinished last frame
    into an invented character (an ETX), and the judges FAILed the reply it seemed to end."""
    edges = frame_edges(START, to_wire_7e1(ord("0"))) + frame_edges(START + 10 * BIT, ord("!"))
    cut = [e for e in frame_edges(START + 20 * BIT, to_wire_7e1(ord("\r")))]
    end = round(START + 22.5 * BIT)  # the capture stops in the third frame's spacing bit 1
    edges += [e for e in cut if e < end]
    found = decode(edges, end)
    assert [chr(d.event.wire & 0x7F) for d in chars(found)] == ["0", "!"]
    assert [d.kind for d in found][-1] == "partial"


def test_a_capture_that_starts_on_an_idle_line_loses_nothing():
    edges = frame_edges(10 * BIT, to_wire_7e1(ord("0")))  # exactly the proving run before it
    (found,) = chars(decode(edges, round(40 * BIT)))
    assert found.event.wire == to_wire_7e1(ord("0"))


def test_a_capture_ended_while_a_character_marked_drops_it_too():
    """The capture stops in a marking data bit of the last frame: with no edge after it the
    rest would read as marking and make up a character ('0' = 0x30 seen as 0x70, 'p');
    the reader knows where the capture ends, so the frame is dropped as cut."""
    edges = frame_edges(START, to_wire_7e1(ord("0")))
    last = frame_edges(START + 10 * BIT, to_wire_7e1(ord("0")))  # bits 4 and 5 mark
    end = round(START + 15.5 * BIT)  # inside bit 5, marking, before the stop bit's centre
    edges += [e for e in last if e < end]
    found = decode(edges, end)
    assert [chr(d.event.wire & 0x7F) for d in chars(found)] == ["0"]
    assert [d.kind for d in found][-1] == "partial"
    whole = decode(edges + [e for e in last if e >= end], round(START + 40 * BIT))
    assert [chr(d.event.wire & 0x7F) for d in chars(whole)] == ["0", "0"]  # not cut: read
