"""The kit's ESP flavours (``-D ESP32``, ``-D ESP8266``) and its Print/Stream classes, as the
widely used EnviroDIY SDI-12 library's ESP path uses them (docs/kit.md): sketches/esp_stream
(our own code) derives a line class from Stream, sends with print()/println() through
write(uint8_t) timed by a 64-us tick (micros() >> 6, 13 ticks a bit, 8-bit wrap-around),
hears the tool's characters from an IRAM_ATTR CHANGE handler, and reads the command with
Stream's readStringUntil on millis(). The tests play the tool's side of the harness
protocol, so what is checked is the kit: the frames come out at the tick-timed bit, the reply
where the sketch put it, and a timed read waits its timeout on the virtual clock."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.kit.conftest import SKETCHES, play_sensor

SKETCH = SKETCHES / "esp_stream"
#: a break, then "0!" (the tool's 1200-baud frames: '0' 0x30, '!' 0x21)
ACKNOWLEDGE = ["break 0 12000", "char 20333 28667 30", "char 28667 37000 21"]
COMMAND_END = 37000
TICK_US = 64


@pytest.fixture(scope="module", params=["ESP32", "ESP8266"])
def esp_stream(kit_build, request) -> Path:
    """The sketch built as each ESP board (it asserts the flavour's F_CPU as it compiles)."""
    return kit_build(SKETCH, defines=(request.param,))


def test_the_stream_reply_goes_out_at_the_tick_timed_bit(esp_stream):
    sent, log = play_sensor(esp_stream, "esp_stream", ACKNOWLEDGE, until=80000, steps=10**6)
    assert [wire for _, _, wire in sent] == [0x30, 0x8D, 0x0A], log  # print("0"), println()
    logged = [(int(t), int(w, 16)) for t, w in re.findall(r"\] F (\d+) ([0-9a-fA-F]+)", log)]
    assert [w for _, w in logged] == [wire for _, _, wire in sent]
    for (start, end, _), (wrote_at, _) in zip(sent, logged, strict=True):
        # the start bit is written right after the sketch logs it (a micros() call later)
        assert 0 <= start - wrote_at <= 2
        # ten bits of 13 ticks, the first cut short by where in its tick it began
        assert 10 * 13 * TICK_US - TICK_US <= end - start <= 10 * 13 * TICK_US
    # the '!' decoded at its stop bit's centre (9.5 bits after its start), then delay(9)
    decoded = 28667 + int(9.5 * 833)
    assert decoded + 9000 <= sent[0][0] <= decoded + 9000 + 20
    assert sent[0][0] - COMMAND_END >= 7930  # the reply's marking, as R-7.0-09 asks


def test_a_timed_read_waits_its_timeout_on_the_virtual_clock(esp_stream):
    """readStringUntil with setTimeout(10) and nothing on the line: Stream's timed read polls
    millis() (each call a call into the core) and returns empty 10 ms later, virtual."""
    _, log = play_sensor(esp_stream, "esp_stream", ["break 0 12000"], until=60000, steps=10**6)
    waits = [(int(a), int(b)) for a, b in re.findall(r"\] T (\d+) (\d+)", log)]
    assert len(waits) >= 3, log
    assert all(b - a in (10, 11) for a, b in waits)
    assert all(b2 >= b1 for (_, b1), (b2, _) in zip(waits, waits[1:], strict=False))
