"""Bus efficiency of the sensor suite on a real-time link.

Serves the reference emulator over RFC 2217 on loopback (``sdi12-conform emulate`` in a child
process), runs the full sensor suite against it with the CLI, and prints what
``verdicts.json`` records under ``run.bus``: the bus-time lower bound (what any recorder
would need for the same exchanges: frames, breaks, the marking after them, the sensor's own
delays and announced measurement times) next to the wall time the run took, and their ratio.

    python benchmarks/bus_efficiency.py [-k EXPR] [--faults NAME,...] [--keep DIR]
    python benchmarks/bus_efficiency.py --bench "--echo --usb-latency 16" --wire 127.0.0.1:4803
    python benchmarks/bus_efficiency.py --attribute DIR   (a kept run: where the rest went)
    python benchmarks/bus_efficiency.py --attribute DIR --on-wire   (the same on the line's clock)

``--tool ARGS`` adds options to the tool's run (``--timing-uncertainty-ms 16``: it widens the
stamps' uncertainty, not the link's declared floor; ``benchmarks/reader_stamps`` sets that
for a run). ``--bench ARGS`` serves the emulator behind ``emulate``'s bench models (an
echoing interface behind an FTDI-style 16 ms latency timer, above), ``--listen HOST:PORT``
where it serves,
``--wire HOST:PORT`` also serves the line on an ``emulate --tap`` there and prints the run on
the line's own clock beside ``run.bus`` (``wire_tap.py``: the bound without the receive
path's stamps, and the adapter floor, the bound plus what the latency timer's delivery of
each answered reply's last character added past the 7.5 ms the bound gives the sensor).

Takes about as long as the suite's bus time (roughly five minutes for every case). The wall
time counts everything the run did on the link's clock: the bus span (first to last event on
the wire) and, after it, the whole-run judges and the reports, which on a loaded machine
take seconds of CPU; both are printed, with the load average before and after, since the
figure moves with the machine's load. Compare two trees one after the other on the same
machine (``PYTHONPATH=OLD python OLD/benchmarks/bus_efficiency.py``, then the new one).

Measured (issue 22, the 2-core machine with four other sessions on it, load average 4-17,
one run after the other): a515f24 268.3 and 267.6 s lower bound (as it counted), 302.8 and
301.0 s span, 309.1 and 304.3 s wall (0.87, 0.88); this tree 262.7, 263.7, 265.2 and
268.0 s lower bound, 295.1, 295.0, 297.2 and 310.6 s span, 302.0, 300.5, 302.5 and 317.6 s
wall (0.87, 0.88, 0.88, 0.84). Issue 22's fourth round, 807fdce and the tree that counts an
aborted measurement's ttt when its data are asked for after it, side by side at load 4: 262.1
against 274.0 s lower bound, 294.7 against 294.9 s wall (0.89, 0.93). Its fifth round (the
look before transmitting counted from the turnaround's end, a hopeless timed probe sent once),
1297dda and this tree side by side at load 3-7: 274.0 against 273.7 s lower bound, 292.3
against 290.3 s span, 295.9 against 294.4 s wall (0.926, 0.930); at load 5-7 275.1 against
274.5, 293.8 against 291.7, 296.0 against 294.0 s (0.929, 0.934). Its sixth round (R-6.1-03's
listening ends with its rule's window; idles counted as marking from the line's last
activity), b999a88 and this tree side by side at load 5-10: 0.907 against 0.915, 0.906
against 0.912, 0.922 against 0.929 (span beyond the bound 20.5/18.9, 26.2/23.6, 19.3/17.7 s).
README's "Measured" and ``--attribute`` say where the rest goes; ``--attribute`` also prints
the look before transmitting beside the late characters the run's meter saw. The children
run in the tree this script imported: ``-m conformance.cli`` imports the package of the
working directory first.
"""

from __future__ import annotations

import argparse
import bisect
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import conformance
from conformance.capture.transcript_io import read_transcript_jsonl
from conformance.emulator_server.process import EmulatorProcess
from conformance.links.bus_time import bus_time, uncounted
from conformance.transcript import TOOL, Event, EventKind, decode_7e1, write_jsonl

sys.path.insert(0, str(Path(__file__).resolve().parent))
from wire_tap import TapRecorder, wire_figures  # noqa: E402

#: an uncounted stretch this long is listening on purpose (a wait, a probe's idle marking),
#: not the turnaround, look and read grace around one exchange
LONG = 0.05


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("-k", dest="keyword", help="only cases matching this expression")
    p.add_argument("--faults", default="", help="emulator faults (default: clean)")
    p.add_argument("--keep", help="write the reports here instead of a temporary folder")
    p.add_argument(
        "--bench",
        default="",
        metavar="ARGS",
        help='serve the emulator behind these bench models, e.g. "--echo --usb-latency 16"',
    )
    p.add_argument(
        "--listen",
        default="127.0.0.1:0",
        metavar="HOST:PORT",
        help="where the emulator serves (default: a free loopback port)",
    )
    p.add_argument(
        "--tool",
        default="",
        metavar="ARGS",
        help='more options for the tool\'s run, e.g. "--timing-uncertainty-ms 16"',
    )
    p.add_argument(
        "--attribute",
        metavar="DIR",
        help="no run: sort the wall beyond the lower bound of a kept run by its causes",
    )
    p.add_argument(
        "--on-wire",
        action="store_true",
        help="with --attribute: the line's clock (wire.jsonl of a --wire run), not the tool's",
    )
    p.add_argument(
        "--wire",
        metavar="HOST:PORT",
        help="also serve the line on a tap there and give the run's figures on the line's own "
        "clock (wire_tap.py: the bound without the receive path's stamps, the adapter floor)",
    )
    args = p.parse_args(argv)
    if args.attribute:
        kept = "wire.jsonl" if args.on_wire else "transcript.jsonl"
        events = read_transcript_jsonl(str(Path(args.attribute) / kept))
        print(attribution(events))
        verdicts = Path(args.attribute) / "verdicts.json"
        if verdicts.exists():
            print(look_figures(json.loads(verdicts.read_text())["run"]["link"]))
        return 0
    out = Path(args.keep or tempfile.mkdtemp(prefix="sdi12-bus-")).resolve()
    # the children start with ``-m conformance.cli``, which imports the package of the working
    # directory first: run them in the tree this script imported, so PYTHONPATH=OLD runs OLD
    os.chdir(Path(conformance.__file__).resolve().parents[1])
    load_before = os.getloadavg()
    extra = ["--faults", args.faults] if args.faults else []
    # EmulatorProcess listens on a free port; a later --listen wins in emulate's parser
    extra += ["--listen", args.listen, *shlex.split(args.bench)]
    if args.wire:
        extra += ["--tap", f"socket://{args.wire}"]
    tap = None
    with EmulatorProcess(*extra) as emulator:
        if args.wire:
            host, port = args.wire.rsplit(":", 1)
            tap = TapRecorder(host, int(port))
        command = [
            sys.executable,
            "-m",
            "conformance.cli",
            "--port",
            emulator.url,
            "--report-dir",
            str(out),
        ]
        if args.keyword:
            command += ["-k", args.keyword]
        command += shlex.split(args.tool)
        started = time.monotonic()
        proc = subprocess.run(command, capture_output=True, text=True)
        process_s = time.monotonic() - started
        heard = tap.stop() if tap is not None else []
    verdicts = out / "verdicts.json"
    if not verdicts.exists():
        print(proc.stdout + proc.stderr)
        return 1
    data = json.loads(verdicts.read_text())
    bus = data["run"]["bus"]
    print(f"suite verdict        {data['summary']['verdict']} (exit {proc.returncode})")
    print(f"frames / breaks      {bus['frames']} / {bus['breaks']}")
    print(f"bus-time lower bound {bus['bus_lower_bound_s']:.1f} s")
    print(f"bus span             {bus['bus_span_s']:.1f} s (first to last event on the wire)")
    print(f"wall time (link)     {bus['wall_s']:.1f} s")
    print(f"efficiency           {bus['efficiency']:.3f} (lower bound / wall time)")
    print(f"whole process        {process_s:.1f} s (pytest start-up and reports included)")
    if args.bench:
        print(f"bench models         {args.bench}")
    if args.tool:
        print(f"tool options         {args.tool}")
    print(f"load average         {_load(load_before)} before, {_load(os.getloadavg())} after")
    print(f"reports              {out}")
    if tap is not None:
        events = read_transcript_jsonl(str(out / "transcript.jsonl"))
        wire = wire_figures(events, heard, _usb_latency(args.bench))
        print(wire.text(bus["bus_lower_bound_s"]))
        write_jsonl(str(out / "wire.jsonl"), wire.placed)
        print(f"                     the events on the line's clock: {out / 'wire.jsonl'}")
    return 0


def attribution(events: list[Event]) -> str:
    """A table of the span's uncounted stretches (:func:`bus_time.uncounted`) by what was
    on the wire either side of them, with the commands before the longest ones: which wait
    of which case the wall beyond the bound went to."""
    wire = sorted((e for e in events if e.kind is not EventKind.NOTE), key=lambda e: e.start)
    starts = [e.start for e in wire]
    commands = _commands(wire)
    command_starts = [start for start, _ in commands]
    rows: dict[str, list] = defaultdict(lambda: [0, 0.0, []])
    for start, end in uncounted(wire):
        before = wire[max(0, bisect.bisect_right(starts, start) - 1)]
        k = bisect.bisect_right(command_starts, start) - 1
        command = commands[k][1] if k >= 0 else "?"
        row = rows[_cause(before, end - start)]
        row[0] += 1
        row[1] += end - start
        row[2].append((end - start, command))
    figures = bus_time(wire)
    lines = [
        f"lower bound {figures.lower_bound:.1f} s, span {figures.span:.1f} s: "
        f"{figures.span - figures.lower_bound:.1f} s uncounted",
        "   seconds  count  cause (commands before the longest)",
    ]
    for cause, (count, seconds, longest) in sorted(rows.items(), key=lambda r: -r[1][1]):
        top = ", ".join(f"{c} {d * 1e3:.0f} ms" for d, c in sorted(longest, reverse=True)[:3])
        lines.append(f"{seconds:10.2f} {count:6d}  {cause} ({top})")
    return "\n".join(lines)


def look_figures(link: dict) -> str:
    """What the look before transmitting (``ToolRecorder.look_before_transmit``: the link's
    declared timing uncertainty, after each turnaround that follows the DUT) rests on, beside
    what the run measured of its characters' lateness (``run.link`` of verdicts.json). The
    look could only be the measured figure where the link measures one; without an echo it
    sees only lower bounds: a batch of bytes, or a character stamped less than a frame after
    the one before, shows that one of them came that much late."""
    timing = (link.get("bench") or {}).get("timing") or {}
    declared = link.get("timing_uncertainty_ms")
    if not timing:
        return f"look before transmitting: {declared} ms declared (no bench figures)"
    reference = timing.get("reference")
    text = (
        f"look before transmitting: {declared} ms declared; the run timed against the "
        f"{'echo of its commands' if reference == 'echo' else 'write time (no echo)'}, "
        f"regular figure {timing['regular_ms']} ms"
    )
    batches, artefacts = timing["batches"], timing["artefacts"]
    return (
        f"{text}; late characters seen: batches worst {batches['worst_ms']} ms "
        f"({batches['samples']}), overlapping frames worst {artefacts['worst_ms']} ms, "
        f"{timing['local_irregularities']} local irregularities"
    )


def _cause(before: Event, length: float) -> str:
    """What the engine was doing in an uncounted stretch, from the event before it."""
    long = length >= LONG
    if before.kind is EventKind.BREAK:
        return "listening after the tool's break" if long else "marking after a break"
    if before.origin != TOOL:
        if long:
            return "listening after the DUT's last character (waits, idle marking)"
        return "turnaround and look before transmitting after the DUT"
    if before.wire & 0x7F == ord("!"):
        if long:
            return "listening after an unanswered command (probes for silence)"
        return "waiting for a reply that did not come (first-character timeout, read grace)"
    return "marking inside a command (partial-command probes)"


def _commands(wire: list[Event]) -> list[tuple[float, str]]:
    """(start, text) of each tool command ending in '!', in order."""
    found: list[tuple[float, str]] = []
    current: list[Event] = []
    for e in wire:
        if e.kind is EventKind.BREAK:
            current = []
        elif e.origin == TOOL:
            current.append(e)
            if e.wire & 0x7F == ord("!"):
                found.append((current[0].start, decode_7e1(current)))
                current = []
    return found


def _usb_latency(bench: str) -> float:
    """The latency-timer period (s) ``--usb-latency MS`` in ``bench`` gives emulate; 0."""
    words = shlex.split(bench)
    for k, word in enumerate(words):
        if word == "--usb-latency" and k + 1 < len(words):
            return float(words[k + 1]) / 1e3
        if word.startswith("--usb-latency="):
            return float(word.split("=", 1)[1]) / 1e3
    return 0.0


def _load(averages: tuple[float, float, float]) -> str:
    return "/".join(f"{a:.2f}" for a in averages)


if __name__ == "__main__":
    sys.exit(main())
