"""A busy bus that measures, as a capture holds it (issue 22, memory26): what a passive
judgement of a long capture keeps per measurement, which ``capture_decode.py``'s bus (every
exchange an ``aD0!`` outside a measurement) never shows.

One cycle of traffic is made once by the tool recorder engine over emulated sensors on a
simulated bus (:mod:`tests.support.bus_of_sensors`'s way), then laid end to end, each copy
shifted in time, for as long as asked; every event of origin ``bus`` (a one-wire capture
infers the directions itself). A cycle holds, on four sensors: an ``aM!`` with its service
request and ``aD0!``; an immediate ``aM1!``; a CRC measurement ``aMC!``; a concurrent round
(``aC!`` to three sensors, ``aD0!``..``aD2!`` each) of which one is aborted by a command to
its sensor before its data; a high-volume binary ``aHB!`` and ASCII ``aHA!`` read past
``aD9!``; and a sensor that answers only a retry (retries and sequences).

    python benchmarks/measuring_bus.py --minutes 60 --keep /tmp/measuring-60.sr

writes the capture (sigrok, 1 MHz) as ``capture_decode.py --keep`` does; ``tests/offline/
test_recorder_measurements_let_go.py`` reads :func:`measuring_bus` as a transcript.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

from conformance.emulator.profile import default_profile
from conformance.emulator.sensor import SensorEmulator
from conformance.protocol.commands import parse_command
from conformance.sensor.bus_round import start_measurement
from conformance.sim.bus import SimBus, SimLink
from conformance.tool_recorder import ToolRecorder
from conformance.transcript import BUS, Event, EventKind

#: the sensors' addresses; the last one answers only a retry (``replies-after-retry``)
ADDRESSES = "0123"
RETRYING = "3"
#: marking (s) between one cycle's last event and the next cycle's first
BETWEEN = 0.2


def _cycle() -> tuple[list[Event], float]:
    """One cycle's events (origin ``bus``, the first starting at 0) and its length (s)."""
    bus = SimBus()
    for a in ADDRESSES:
        profile = replace(default_profile(), address=a, optional=f"SN000{a}")
        faults = ("replies-after-retry",) if a == RETRYING else ()
        bus.attach(SensorEmulator(profile, faults, name=f"sensor-{a}"))
    recorder = ToolRecorder(SimLink(bus))
    link = recorder.link
    recorder.measure(parse_command("0M!"))  # waits for the service request, then aD0!
    recorder.measure(parse_command("1M1!"))  # immediate: no service request
    recorder.measure(parse_command("2MC!"))
    started = [start_measurement(recorder, f"{a}C!") for a in "012"]
    recorder.transact("1I!")  # aborts sensor 1's concurrent measurement (R-4.4.7.1-01)
    ends = [m.reply_end + m.ttt for m in started if m.reply_end is not None and m.ttt]
    link.wait_until(max([link.now(), *ends]) + 0.1)
    for m in started:
        recorder.collect(m, force_break=True)
    recorder.measure(parse_command("0HB!"))
    recorder.measure(parse_command("2HA!"))
    recorder.transact(f"{RETRYING}I!")  # answered only at its retry
    recorder.measure(parse_command(f"{RETRYING}M1!"))
    events = [replace(e, origin=BUS) for e in bus.transcript.events if e.kind is not EventKind.NOTE]
    first = events[0].start
    events = [replace(e, start=e.start - first, end=e.end - first) for e in events]
    return events, max(e.end for e in events) + BETWEEN


def measuring_bus(seconds: float) -> list[Event]:
    """A bus that measures for ``seconds`` (whole cycles, at least one), from t = 0.05 s."""
    events, length = _cycle()
    out: list[Event] = []
    at = 0.05
    while not out or at + length <= seconds:
        out += [replace(e, start=e.start + at, end=e.end + at) for e in events]
        at += length
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--minutes", type=float, default=60.0)
    p.add_argument("--rate", type=float, default=1e6, help="sample rate (Hz)")
    p.add_argument("--keep", required=True, help="write the capture here")
    args = p.parse_args(argv)
    from conformance.capture import export_events

    start = time.perf_counter()
    events = measuring_bus(args.minutes * 60)
    info = export_events(events, args.keep, sample_rate=args.rate)
    chars = sum(e.kind is EventKind.CHAR for e in events)
    print(
        f"{args.minutes:g} min: {chars} characters, {len(events) - chars} breaks, "
        f"{info.samples / 1e9:.2f} G samples, {Path(args.keep).stat().st_size / 1e6:.1f} MB,"
        f" {time.perf_counter() - start:.1f} s"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
