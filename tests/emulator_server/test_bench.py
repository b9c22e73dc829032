"""The emulator's bench models: what echoing, batching, jittery and RTS-switched interfaces do
to the recorder's view of the line (conformance.emulator_server.bench and the real-time line)."""

from __future__ import annotations

import threading
import time

import pytest

from conformance.emulator_server.bench import (
    BenchModel,
    Delivery,
    spacing_as_received,
    spacing_runs,
)
from conformance.emulator_server.realtime import RealTimeLine
from conformance.protocol.timing import CHAR_TIME


def test_a_break_reads_as_nul_at_the_stop_bit_sample():
    byte, offset = spacing_as_received(13e-3)
    assert byte == 0x00 and offset == pytest.approx(9.5 / 1200)


def test_a_short_pulse_reads_as_a_byte_with_its_low_bits_zero():
    byte, _ = spacing_as_received(5e-3)  # 6 bit times: start bit and data bits 0..4 spacing
    assert byte == 0xE0
    assert spacing_as_received(0.1e-3) is None  # under half a bit: not seen


def test_a_nul_at_another_rate_is_nine_bit_times_of_spacing():
    assert spacing_runs(0x00, 4800) == [(0.0, pytest.approx(9 / 4800))]
    assert spacing_runs(0x00, 720)[0][1] == pytest.approx(12.5e-3)
    runs = spacing_runs(0x55, 2400)  # 0 1010 1010 1 -> a spacing run per 0 bit
    assert len(runs) == 5


def test_usb_latency_delivers_in_timer_ticks_and_never_reorders():
    delivery = Delivery(BenchModel(usb_latency=16e-3))
    assert delivery.time(0.001) == pytest.approx(0.016)
    assert delivery.time(0.0165) == pytest.approx(0.032)
    jittery = Delivery(BenchModel(jitter=5e-3, seed=3))
    times = [jittery.time(k * 1e-4) for k in range(200)]
    assert times == sorted(times)
    assert all(t - k * 1e-4 <= 5e-3 + 1e-12 for k, t in enumerate(times))


class _Quiet:
    """A device that hears and never speaks."""

    name = "quiet"

    def __init__(self) -> None:
        self.chars: list[int] = []
        self.breaks: list[tuple[float, float]] = []

    def on_break(self, start: float, end: float) -> None:
        self.breaks.append((start, end))

    def on_char(self, wire: int, start: float, end: float) -> None:
        self.chars.append(wire)

    def next_frame(self):
        return None

    def pop_frame(self):
        raise AssertionError


def _line(bench: BenchModel) -> tuple[RealTimeLine, _Quiet, list[tuple[float, int]]]:
    device = _Quiet()
    heard: list[tuple[float, int]] = []
    lock = threading.Lock()

    def send(data: bytes) -> None:
        with lock:
            heard.extend((time.perf_counter(), b) for b in data)

    return RealTimeLine(device, send, bench=bench).start(), device, heard


def _wait_for(predicate, bound: float = 1.0) -> None:
    deadline = time.monotonic() + bound
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.005)


def test_echo_returns_the_recorders_characters_at_their_stop_bits():
    line, device, heard = _line(BenchModel(echo=True))
    try:
        at = line.now()
        line.tool_bytes(b"0I!", at)
        _wait_for(lambda: len(heard) == 3)
        assert [b for _t, b in heard] == list(b"0I!")
        assert heard[-1][0] - at >= 3 * CHAR_TIME - 1e-3
        assert device.chars == list(b"0I!")
    finally:
        line.stop()


def test_echo_of_a_break_is_a_nul():
    line, device, heard = _line(BenchModel(echo=True))
    try:
        line.break_on()
        time.sleep(0.013)
        line.break_off()
        # the echo and the sensor's view of the break come from the line's thread one after
        # the other: wait for both (a starved test process may look in between)
        _wait_for(lambda: len(heard) == 1 and len(device.breaks) == 1)
        assert [b for _t, b in heard] == [0x00]
        assert len(device.breaks) == 1
    finally:
        line.stop()


def test_a_nul_sent_at_a_lower_rate_is_a_spacing_pulse_for_the_sensor():
    line, device, _heard = _line(BenchModel())
    try:
        line.tool_bytes(b"\x00", line.now(), baud=1800)
        _wait_for(lambda: bool(device.breaks))
        ((start, end),) = device.breaks
        assert end - start == pytest.approx(5e-3)
        assert device.chars == []
    finally:
        line.stop()


def test_without_rts_the_recorders_characters_never_reach_the_line():
    line, device, _heard = _line(BenchModel(require_rts=True))
    try:
        line.tool_bytes(b"0!", line.now())
        time.sleep(0.05)
        assert device.chars == []
        line.set_rts(True)
        line.tool_bytes(b"0!", line.now())
        _wait_for(lambda: len(device.chars) == 2)
        assert device.chars == list(b"0!")
    finally:
        line.stop()
