"""Models of the interfaces real benches put between a recorder and the SDI-12 line.

The emulated line is exact; a bench is not. These models sit between the line and the
recorder connected to it, so the tool's handling of real interfaces can be tested without
hardware (issue: real bench):

- **echo**: a UART on a diode-and-resistor interface (or a level shifter whose receiver stays
  on) hears every character the recorder sends, at its stop bit; spacing (a break) is heard
  as whatever a 1200-baud receiver makes of it (:func:`spacing_as_received`);
- **USB latency**: an FTDI-style chip holds received bytes until its latency timer ticks and
  sends them in a batch;
- **jitter**: each batch is delayed a further random 0..J ms (order kept), as a busy host or
  a network adds;
- **RTS**: with a transmit-enable line, the recorder's characters reach the bus only while it
  raises RTS, and the sensor's reply is lost while RTS is still raised (the recorder's driver
  holds the line).

Everything here is pure arithmetic on times;
:class:`~conformance.emulator_server.realtime.RealTimeLine`
calls it.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from ..protocol.timing import BAUD

SAMPLE_STOP = 9.5  # bit times: where a receiver samples the stop bit of a frame


@dataclass(frozen=True)
class BenchModel:
    """What sits between the emulated line and the recorder (all off: a perfect interface)."""

    echo: bool = False
    usb_latency: float = 0.0  # s: latency-timer period (FTDI default 16 ms); 0 = none
    jitter: float = 0.0  # s: extra random delay of each delivery, uniform in [0, jitter]
    require_rts: bool = False
    seed: int = 1

    def describe(self) -> str:
        parts = []
        if self.echo:
            parts.append("echo")
        if self.usb_latency:
            parts.append(f"USB latency timer {self.usb_latency * 1e3:g} ms")
        if self.jitter:
            parts.append(f"jitter 0..{self.jitter * 1e3:g} ms")
        if self.require_rts:
            parts.append("RTS-switched driver")
        return ", ".join(parts) or "ideal interface"


@dataclass
class Delivery:
    """When bytes reach the recorder: latency-timer batches plus jitter, never reordered."""

    model: BenchModel
    _last: float = -math.inf
    _rng: random.Random = field(init=False)

    def __post_init__(self) -> None:
        self._rng = random.Random(self.model.seed)

    def time(self, ready: float) -> float:
        """The recorder receives a byte that the interface had complete at ``ready`` (s)."""
        at = ready
        period = self.model.usb_latency
        if period > 0:
            at = math.ceil(ready / period) * period  # the next tick of a free-running timer
        if self.model.jitter > 0:
            at += self._rng.uniform(0.0, self.model.jitter)
        at = max(at, self._last)  # one pipe: a later byte never overtakes an earlier one
        self._last = at
        return at


def spacing_as_received(duration: float, baud: int = BAUD) -> tuple[int, float] | None:
    """What a receiver at ``baud`` makes of a spacing pulse of ``duration`` s on a marking
    line: ``(byte, offset)``, the byte read and when (s after the pulse began) it is read, at
    the stop-bit sample. A pulse of 8.5 bit times or more reads as 0x00 (a break: framing
    error); a shorter one as a byte whose low data bits are 0 and the rest 1; one shorter than
    half a bit is not seen (None)."""
    bits = duration * baud
    if bits < 0.5:
        return None
    zeros = min(8, max(0, math.ceil(bits - 1.5)))  # data bit j is sampled at 1.5 + j bits
    byte = (0xFF << zeros) & 0xFF
    return byte, SAMPLE_STOP / baud


def spacing_runs(byte: int, baud: int) -> list[tuple[float, float]]:
    """The spacing stretches (start, end offsets in s) of one 8N1 frame sent at ``baud``: what
    a character at another bit rate is on a 1200-baud line (a NUL: one run of 9 bit times)."""
    bits = [0] + [(byte >> k) & 1 for k in range(8)] + [1]
    runs: list[tuple[float, float]] = []
    start: int | None = None
    for k, bit in enumerate(bits):
        if bit == 0 and start is None:
            start = k
        elif bit == 1 and start is not None:
            runs.append((start / baud, k / baud))
            start = None
    return runs
