"""The polarity probe's short path (``capture.decode._choose_polarity``): the first
``PROBE_EDGES`` edges decide only when they read cleanly one way; anything less clear is
decided on the whole first block, as before the short path existed. Here on edges written
by hand: a capture whose first edges alone would pick the wrong polarity, and clean traffic
in either polarity, where the short probe decides and agrees with the whole block."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings

from conformance.capture import decode as capture_decode
from conformance.capture import uart_bulk
from conformance.capture.edges import Edges
from conformance.capture.uart import Framing
from conformance.transcript import to_wire_7e1
from tests.capture.test_uart_bulk import streams

RATE = 100_000.0  # ticks per second, as the export writes
BIT = RATE / 1200
FRAMING = Framing.parse("7E1")
TEXT = "0D0!0+3.14-2.5+17\r\n"


def frames(start: float, count: int, idle: int) -> tuple[list[int], float]:
    """Edges of ``count`` 7E1 characters of :data:`TEXT` back to back with a bit of marking
    between them, on a line idling at raw level ``idle`` (1: UART levels, 0: the SDI-12 line's),
    and the tick after the last one."""
    edges: list[int] = []
    t = start
    for k in range(count):
        wire = to_wire_7e1(ord(TEXT[k % len(TEXT)]))
        uart_levels = [0] + [(wire >> i) & 1 for i in range(8)] + [1]
        prev = 1
        for j, level in enumerate(uart_levels):
            if level != prev:
                edges.append(round(t + j * BIT))
                prev = level
        t += 11 * BIT  # ten bits and one of marking
    del idle  # a raw level flips every edge alike: the polarity is the initial level's
    return edges, t


def choose(edges: list[int], initial_level: int) -> tuple[bool, str]:
    found = Edges("test", "D0", ["D0"], RATE, 1 / RATE, initial_level, [edges])
    return capture_decode._choose_polarity(found, edges, 1200, FRAMING)


def short_scores(edges: list[int], initial_level: int) -> dict[bool, int]:
    short = edges[: capture_decode.PROBE_EDGES]
    return {
        inv: capture_decode._score(
            [
                capture_decode._code(d)
                for d in capture_decode.decode(
                    [short], initial_level=initial_level, tick_rate=RATE, baud=1200, invert=inv
                )
            ]
        )
        for inv in (False, True)
    }


def full_choice(edges: list[int], initial_level: int) -> bool:
    """The whole-block choice, as the probe made it before its short path."""
    scores = {
        inv: capture_decode._score(
            [
                capture_decode._code(d)
                for d in capture_decode.decode(
                    [edges], initial_level=initial_level, tick_rate=RATE, baud=1200, invert=inv
                )
            ]
        )
        for inv in (False, True)
    }
    assert scores[False] != scores[True]
    return scores[True] > scores[False]


def test_first_edges_that_alone_would_pick_wrong_fall_back_to_the_whole_block():
    # raw level 0 at first: the SDI-12 line's levels, frames with a glitch every 40 of them
    # (not clean: the short probe may not decide); then the line flips to UART levels for
    # good (one edge and a long marking), and three times as many clean UART frames follow
    edges: list[int] = []
    t = 20 * BIT
    while len(edges) < capture_decode.PROBE_EDGES + 200:
        part, t = frames(t, 40, idle=0)
        edges += part
        edges += [round(t + 2 * BIT), round(t + 2 * BIT) + 3]  # a 30 us spike
        t += 4 * BIT
    # an odd number of edges flips the raw level: from here on UART levels (idle high)
    edges.append(round(t + 20 * BIT))
    part, t = frames(t + 60 * BIT, 3 * len(edges) // 4, idle=1)
    edges += part
    # the first edges alone score the line polarity higher...
    scores = short_scores(edges, initial_level=0)
    assert scores[True] > scores[False]
    # ...but with glitches: not decisive, so the whole block decides, and it says UART
    assert full_choice(edges, initial_level=0) is False
    inverted, why = choose(edges, initial_level=0)
    assert inverted is False
    assert "UART" in why


@pytest.mark.parametrize("initial_level", [1, 0])
def test_clean_traffic_is_decided_by_the_short_probe_as_the_whole_block_decides(
    initial_level, monkeypatch
):
    edges, _ = frames(20 * BIT, 1200, idle=initial_level)
    assert len(edges) > 2 * capture_decode.PROBE_EDGES
    whole = full_choice(edges, initial_level)
    assert whole is (initial_level == 0)
    seen: list[int] = []
    name = "decode_batches" if capture_decode.BULK else "decode"  # the decoder the probe uses
    real_decode = getattr(capture_decode, name)

    def counting(chunks, **kw):
        chunks = list(chunks)
        seen.append(sum(map(len, chunks)))
        return real_decode(chunks, **kw)

    monkeypatch.setattr(capture_decode, name, counting)
    inverted, why = choose(edges, initial_level)
    assert inverted is whole
    assert "detected from clean frames" in why
    assert seen == [capture_decode.PROBE_EDGES] * 2  # the whole block never decoded twice


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(streams())
def test_probe_codes_are_the_decoded_items_codes(found):
    """The probe's codes, read from the bulk decoder's batches without an item made of each
    certified frame, are those of the items the decoder gives (as the probe decodes: t0 0,
    no uncertainty), item for item, in bulk and by the reference decoder."""
    chunks, kw = found
    edges = [e for c in chunks for e in c]
    line = {k: kw[k] for k in ("initial_level", "tick_rate", "baud", "invert", "framing")}
    items = uart_bulk.decode([list(edges)], **line)
    expected = [capture_decode._code(d) for d in items]
    assert capture_decode._probe_codes(list(edges), **line) == expected
    assert [capture_decode._code(d) for d in capture_decode.decode([list(edges)], **line)] == (
        expected
    )
