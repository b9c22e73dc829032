"""The UART decoder (``conformance.capture.uart``) on edges written here by hand: a 7E1 frame
reads as its character, a parity error and a framing error are flagged, a 4 % fast sender is
measured as such, and a 13 ms spacing is a break (R-4.1-01, R-7.0-01/-04 rest on these)."""

from __future__ import annotations

import pytest

from conformance.capture import uart
from conformance.transcript import EventKind, to_wire_7e1

RATE = 1_000_000.0  # ticks per second: a 1 MHz logic analyser
BIT = RATE / 1200  # ticks per bit at 1200 baud


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


def decode(edges: list[int], end: int) -> list[uart.Decoded]:
    return list(uart.decode([edges], initial_level=1, tick_rate=RATE, end_tick=lambda: end))


def chars(found: list[uart.Decoded]) -> list[uart.Decoded]:
    return [d for d in found if d.event is not None and d.event.kind is EventKind.CHAR]


def test_a_frame_reads_as_its_character_at_its_stamps():
    edges = frame_edges(1000, to_wire_7e1(ord("0"))) + frame_edges(1000 + 10 * BIT, ord("!"))
    found = chars(decode(edges, round(1000 + 40 * BIT)))
    assert [d.event.wire for d in found] == [to_wire_7e1(ord("0")), to_wire_7e1(ord("!"))]
    assert found[0].start == pytest.approx(1000 / RATE, abs=2 / RATE)
    assert found[0].end == pytest.approx((1000 + 10 * BIT) / RATE, abs=2 / RATE)
    assert not any(d.parity_error or d.framing_error for d in found)


def test_a_parity_error_and_a_spacing_stop_bit_are_flagged():
    wrong_parity = to_wire_7e1(ord("1")) ^ 0x80
    edges = frame_edges(1000, wrong_parity) + frame_edges(1000 + 20 * BIT, ord("2"), stop=0)
    found = chars(decode(edges, round(1000 + 60 * BIT)))
    assert found[0].parity_error and not found[0].framing_error
    assert found[1].framing_error


@pytest.mark.parametrize("off", [0.96, 1.04])
def test_a_sender_4_percent_off_is_measured_as_such(off):
    """R-4.1-01 is judged from this figure: 1200 baud within 2 % (decision A14)."""
    bit = BIT * off
    edges = frame_edges(1000, to_wire_7e1(ord("U")), bit)  # 0x55: an edge at every bit
    (found,) = chars(decode(edges, round(1000 + 40 * bit)))
    assert found.baud_error_pct == pytest.approx((1 / off - 1) * 100, abs=0.5)


def test_a_13_ms_spacing_is_a_break_and_a_short_one_is_not():
    long_start, short_start = 1000, round(1000 + 30e-3 * RATE)
    edges = [long_start, long_start + round(13e-3 * RATE)]
    edges += [short_start, short_start + round(5e-3 * RATE)]
    found = decode(edges, round(short_start + 50e-3 * RATE))
    breaks = [d for d in found if d.event is not None and d.event.kind is EventKind.BREAK]
    assert len(breaks) == 1
    assert breaks[0].event.end - breaks[0].event.start == pytest.approx(13e-3, abs=1e-5)
