"""Decoding a long logic-analyzer capture of a busy SDI-12 bus: wall time and peak memory.

Generates continuous traffic (break, ``aD0!``, an 18-character reply, a short pause, over and
over, addresses 0-9), writes it as a one-channel sigrok session at 1 MHz with the package's own
streaming writer, then decodes it with ``decode_capture`` in a fresh child process so that the
peak resident memory reported is the decoder's alone.

    python benchmarks/capture_decode.py [--minutes 60] [--rate 1e6] [--keep PATH] [--judge]

Target (issue 11): a one-hour 1 MHz capture in under 60 s on 2 cores, in bounded memory.
``--judge`` also judges it whole (``sdi12-conform judge``: ten sensors and the recorder, their
reports written) in a child process and gives its wall time and peak memory; issue 22's
target is 30 s for the hour.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1


def busy_bus(seconds: float) -> list[Event]:
    """Back-to-back exchanges: the busiest a recorder polling ten sensors keeps the bus."""
    events: list[Event] = []
    t = 0.05
    n = 0
    while t < seconds - 0.3:
        a = str(n % 10)
        events.append(Event(EventKind.BREAK, TOOL, t, t + 0.0125))
        t += 0.0125 + CHAR_TIME
        for origin, text, after in (
            (TOOL, f"{a}D0!", 0.0095),
            (DUT, f"{a}+1.23-45.6+7.891\r\n", 0.020),
        ):
            for c in text:
                events.append(
                    Event(EventKind.CHAR, origin, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c)))
                )
                t += CHAR_TIME
            t += after
        n += 1
    return events


def own_peak_mb() -> float:
    """This process's own peak resident memory (MB): the high-water mark of its address space
    (``VmHWM``). Not ``ru_maxrss``: Linux carries that over an exec from the address space
    before it, and subprocess starts a child by vfork, so a child reported its parent's peak
    (the busy bus just generated) whenever that was the larger."""
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024


def judge_child(path: str, reports: str) -> None:
    """``sdi12-conform judge`` of ``path`` into ``reports`` in this (child) process; prints its
    exit status and this process's own peak as JSON (``tests/offline/test_judge_memory.py``
    runs it too)."""
    from conformance.cli import main

    try:
        code = main(["judge", path, "--report-dir", reports])
    except SystemExit as exc:
        code = exc.code
    print(json.dumps({"code": code, "peak_mb": own_peak_mb()}))


def decode_child(path: str) -> None:
    from conformance.capture import decode_capture

    start = time.perf_counter()
    d = decode_capture(path)
    wall = time.perf_counter() - start
    peak = own_peak_mb()
    print(
        json.dumps(
            {
                "decode_s": wall,
                "peak_rss_mb": peak,
                "events": len(d.events),
                "chars": d.chars,
                "breaks": d.breaks,
                "errors": d.framing_errors + d.parity_errors + d.glitches,
            }
        )
    )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--minutes", type=float, default=60.0)
    p.add_argument("--rate", type=float, default=1e6, help="sample rate (Hz)")
    p.add_argument("--keep", help="write the capture here and keep it")
    p.add_argument("--judge", action="store_true", help="also judge it (sdi12-conform judge)")
    p.add_argument("--decode-only", help=argparse.SUPPRESS)
    p.add_argument("--judge-only", nargs=2, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.judge_only:
        judge_child(*args.judge_only)
        return 0
    if args.decode_only:
        decode_child(args.decode_only)
        return 0
    from conformance.capture import export_events

    seconds = args.minutes * 60
    tmp = None
    path = args.keep
    if path is None:
        tmp = tempfile.TemporaryDirectory()
        path = os.path.join(tmp.name, "busy.sr")
    start = time.perf_counter()
    events = busy_bus(seconds)
    info = export_events(events, path, sample_rate=args.rate)
    gen = time.perf_counter() - start
    chars = sum(e.kind is EventKind.CHAR for e in events)
    print(
        f"generated {args.minutes:g} min at {args.rate / 1e6:g} MHz: {info.samples / 1e9:.2f} G "
        f"samples, {chars} characters, {len(events) - chars} breaks, "
        f"{os.path.getsize(path) / 1e6:.1f} MB on disk, in {gen:.1f} s"
    )
    out = subprocess.run(
        [sys.executable, __file__, "--decode-only", path],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    r = json.loads(out)
    ok = r["chars"] == chars and r["breaks"] == len(events) - chars and r["errors"] == 0
    print(
        f"decoded in {r['decode_s']:.1f} s wall ({info.samples / r['decode_s'] / 1e6:.0f} M "
        f"samples/s), peak RSS {r['peak_rss_mb']:.0f} MB, {r['events']} events"
        f"{'' if ok else ' (MISMATCH with what was written)'}"
    )
    if args.minutes < 60:
        est = r["decode_s"] * 60 / args.minutes
        print(f"extrapolated to one hour: {est:.0f} s (linear in samples)")
    if args.judge:
        ok = judge(path) and ok
    if tmp is not None:
        tmp.cleanup()
    return 0 if ok else 1


def judge(path: str) -> bool:
    """``sdi12-conform judge`` of the capture in a child process: its wall time, its peak
    memory and its exit status (2: incomplete, as a recording with no measurement is)."""
    with tempfile.TemporaryDirectory() as reports:
        start = time.perf_counter()
        done = subprocess.run(
            [sys.executable, __file__, "--judge-only", path, reports],
            capture_output=True,
            text=True,
        )
        wall = time.perf_counter() - start
        lines = done.stdout.strip().splitlines()
        found = json.loads(lines[-1]) if done.returncode == 0 and lines else {}
        folders = sorted(p.name for p in os.scandir(reports) if p.is_dir())
    code, peak = found.get("code"), found.get("peak_mb", float("nan"))
    print(
        f"judged in {wall:.1f} s wall, peak RSS {peak:.0f} MB (the judging child's own), exit "
        f"{code}, report sets: {', '.join(folders)}"
    )
    return code in (0, 1, 2) and len(folders) == 11


if __name__ == "__main__":
    sys.exit(main())
