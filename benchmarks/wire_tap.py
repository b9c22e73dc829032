"""What the emulated line itself carried during a bus run, beside the tool's own transcript.

Behind a bench model (``emulate --echo --usb-latency 16``) the tool stamps every character
where its receive path delivered it: the sensor's replies and the echoes of its own commands
come in the adapter's latency-timer batches, up to 16 ms late, so its transcript is the wire
seen through the adapter. ``run.bus`` (the contract) is computed on that transcript. This
module records the line as ``emulate --tap`` serves it (each character at its stop bit on the
line, a break as the 0x00 a UART reads at its stop-bit sample), puts each of the tool's
events at the time the line carried it, and gives two figures beside ``run.bus``, for
``benchmarks/bus_efficiency.py --wire``:

- the **wire bound**: the same lower bound (:func:`~conformance.links.bus_time.bus_time`),
  computed on the line's own times: what a recorder with exact stamps would be credited;
- the **adapter floor**: that bound plus, after each reply character the tool answered
  (a turnaround), what the adapter's delivery added beyond the 7.5 ms the bound already
  gives the sensor to release the line (R-7.0-11). A recorder behind the adapter sees the
  last character only when the adapter delivers it, so it cannot start its next
  transmission sooner than ``max(7.5 ms, delivery lateness)`` after the character ended.
  The delivery is the model's: the first tick of a free-running latency timer at or after
  the stop bit (:func:`_tick_phase` finds the ticks).
- the **delivery floor**: that bound plus, after each reply character the tool answered,
  the whole of the delivery's lateness. The adapter floor is a recorder's that knew where
  on the line the character ended; one that sees the line only through the adapter does not
  (the character may have ended just before the tick that delivered it), so it gives the
  sensor its 7.5 ms from the delivery, not from the stop bit, as the tool does
  (``Link.received_by``). No recorder that keeps R-7.0-11 behind such an adapter, without a
  model of its timer, turns around sooner (issue 22, usb13).

Neither is ``run.bus``: both need the tap, which no real bench has.
"""

from __future__ import annotations

import math
import socket
import statistics
import threading
import time
from dataclasses import dataclass

from conformance.emulator_server.bench import SAMPLE_STOP
from conformance.links.bus_time import _announced_waits, _gaps, _own_spans, _sweep
from conformance.protocol.timing import BAUD, CHAR_TIME, RELEASE_LINE
from conformance.transcript import TOOL, Event, EventKind

#: where the tap reads a break after it began (s): a UART samples the stop bit 9.5 bits in
BREAK_HEARD = SAMPLE_STOP / BAUD
#: bins of a latency-timer period in which :func:`_tick_phase` counts the stamps' phases
PHASE_BINS = 160
#: how far the alignment looks ahead for the next equal byte when the two sequences differ
RESYNC = 8


class TapRecorder:
    """Reads an ``emulate --tap`` listener in a thread: (perf_counter s, byte) per byte."""

    def __init__(self, host: str, port: int, wait: float = 5.0) -> None:
        deadline = time.monotonic() + wait
        while True:
            try:
                self.sock = socket.create_connection((host, port), timeout=1.0)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock.settimeout(0.2)
        self.heard: list[tuple[float, int]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, name="wire-tap", daemon=True)
        self._thread.start()

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.sock.recv(4096)
            except TimeoutError:
                continue
            except OSError:
                return
            if not data:
                return
            at = time.perf_counter()
            # bytes read together: back to back, the last one whole now (a late wake-up)
            for k, byte in enumerate(data):
                self.heard.append((at - (len(data) - 1 - k) * CHAR_TIME, byte))

    def stop(self) -> list[tuple[float, int]]:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.sock.close()
        return self.heard


def _byte(e: Event) -> int:
    return 0 if e.kind is EventKind.BREAK else e.wire


def align(events: list[Event], heard: list[tuple[float, int]]) -> list[tuple[Event, float]]:
    """Each of the tool's wire events with the tap time of the same byte on the line, in the
    tool's recorded order; events the tap did not carry (or carried otherwise) are left
    out. Greedy: equal bytes pair up, a difference is skipped on whichever side finds the
    other's byte within :data:`RESYNC` places."""
    pairs: list[tuple[Event, float]] = []
    i = j = 0
    while i < len(events) and j < len(heard):
        if _byte(events[i]) == heard[j][1]:
            pairs.append((events[i], heard[j][0]))
            i += 1
            j += 1
            continue
        ahead = next((d for d in range(1, RESYNC) if j + d < len(heard)
                      and heard[j + d][1] == _byte(events[i])), None)  # fmt: skip
        behind = next((d for d in range(1, RESYNC) if i + d < len(events)
                       and _byte(events[i + d]) == heard[j][1]), None)  # fmt: skip
        if ahead is not None and (behind is None or ahead <= behind):
            j += ahead
        elif behind is not None:
            i += behind
        else:
            i, j = i + 1, j + 1
    return pairs


@dataclass(frozen=True)
class WireFigures:
    """The run on the line's own clock (s)."""

    matched: int  # events placed on the line
    unmatched: int  # the tool's wire events the tap did not carry as recorded
    bound: float  # the lower bound on the line's times
    span: float
    adapter_floor: float  # the bound plus the adapter's delivery beyond the release time
    delivery_floor: float  # the bound plus the whole delivery lateness of answered replies
    turnarounds: int  # reply characters the tool answered
    lateness_mean: float  # delivery lateness of those characters
    lateness_worst: float
    placed: tuple[Event, ...] = ()  # the tool's events on the line's clock (wire.jsonl)

    def text(self, tool_bound: float) -> str:
        return "\n".join(
            [
                f"wire (tap)           {self.matched} events on the line's clock "
                f"({self.unmatched} not matched)",
                f"wire bound           {self.bound:.1f} s (run.bus's bound on the tool's "
                f"stamps: {tool_bound:.1f} s)",
                f"wire span            {self.span:.1f} s",
                f"adapter floor        {self.adapter_floor:.1f} s (+ delivery past 7.5 ms "
                f"after {self.turnarounds} answered replies: lateness mean "
                f"{self.lateness_mean * 1e3:.1f} ms, worst {self.lateness_worst * 1e3:.1f} ms)",
                f"delivery floor       {self.delivery_floor:.1f} s (+ the whole lateness: "
                "the sensor's 7.5 ms counted from the delivery)",
            ]
        )


def wire_figures(
    events: list[Event], heard: list[tuple[float, int]], tick: float = 0.0
) -> WireFigures:
    """The tool's events (a transcript) placed on the line's clock, and their figures;
    ``tick``: the bench's latency-timer period (s; 0: none, the floor is the bound)."""
    recorded = [e for e in events if e.kind is not EventKind.NOTE]
    pairs = align(recorded, heard)
    placed: list[Event] = []
    host_breaks: list[float] = []  # the tool's clock less the tap's, at each host-timed break
    for e, at in pairs:
        if e.kind is EventKind.BREAK:
            start = at - BREAK_HEARD
            moved = Event(e.kind, e.origin, start, start + e.duration, wire=e.wire, text=e.text)
            if "timed by the host" in e.text:
                host_breaks.append(e.start - start)
        else:
            moved = Event(e.kind, e.origin, at - CHAR_TIME, at, wire=e.wire)
        placed.append(moved)
    placed.sort(key=lambda e: e.start)
    if not placed:
        return WireFigures(0, len(recorded), 0.0, 0.0, 0.0, 0.0, 0, 0.0, 0.0)
    spans = [*_own_spans(placed), *_gaps(placed), *_announced_waits(placed)]
    bound = _sweep(sorted(spans))
    phase = _tick_phase(recorded, host_breaks, tick)
    extra: list[tuple[float, float]] = []
    blind: list[tuple[float, float]] = []  # the same, the 7.5 ms counted from the delivery
    lateness: list[float] = []
    for a, b in zip(placed, placed[1:], strict=False):
        if phase is not None and a.origin != TOOL and a.kind is EventKind.CHAR and b.origin == TOOL:
            late = phase + math.ceil((a.end - phase) / tick) * tick - a.end
            lateness.append(late)
            if late > RELEASE_LINE:
                extra.append((a.end + RELEASE_LINE, a.end + min(late, b.start - a.end)))
            if late > 0:
                blind.append(
                    (a.end + RELEASE_LINE, a.end + min(RELEASE_LINE + late, b.start - a.end))
                )
    floor = _sweep(sorted([*spans, *extra]))
    return WireFigures(
        matched=len(placed),
        unmatched=len(recorded) - len(placed),
        bound=bound,
        span=placed[-1].end - placed[0].start,
        adapter_floor=floor,
        delivery_floor=_sweep(sorted([*spans, *blind])),
        turnarounds=len(lateness),
        lateness_mean=sum(lateness) / len(lateness) if lateness else 0.0,
        lateness_worst=max(lateness, default=0.0),
        placed=tuple(placed),
    )


def _tick_phase(recorded: list[Event], host_breaks: list[float], tick: float) -> float | None:
    """Where (s, on the tap's clock, modulo ``tick``) the bench's free-running latency timer
    ticks, so each reply character's delivery is the first tick at or after its stop bit
    (``emulator_server.bench.Delivery``). The ticks on the tool's clock: the commonest
    phase of its reply characters' stamp ends (a character the no-overlap rule did not move
    is stamped at its arrival, a tick); the two clocks' offset: the median over the
    host-timed breaks, whose stamps are the tool's own clock at the break's start. None
    without a tick or a break to tie the clocks."""
    if tick <= 0 or not host_breaks:
        return None
    bins = [0] * PHASE_BINS
    for e in recorded:
        if e.kind is EventKind.CHAR and e.origin != TOOL:
            bins[int(e.end % tick / tick * PHASE_BINS) % PHASE_BINS] += 1
    commonest = max(range(PHASE_BINS), key=bins.__getitem__)
    on_tool_clock = (commonest + 0.5) * tick / PHASE_BINS
    return (on_tool_clock - statistics.median(host_breaks)) % tick
