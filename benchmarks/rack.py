"""A rack's wall time against its slowest DUT run alone, and the production profile's bus
time per sensor (issue 23, item 4).

Serves N reference emulators over RFC 2217 on loopback (``sdi12-conform emulate`` child
processes; the last one with ``--faults``), runs each DUT alone with the CLI, one after
another, then all of them as one rack (``--port A --port B ...``), with the same selection
(default ``--profile production``) and ``--plan never`` in both (the dry run's cache would
otherwise favour whichever ran second). Prints each wall time (the process's, start to
exit), the rack's over the slowest alone (target: at most 1.2), and each sensor's bus time
from its verdicts.json (``run.bus``: the lower bound any recorder needs, and the link's
wall from the first to the last event).

    python benchmarks/rack.py [--duts 3] [--faults wrong-crc] [--profile production | -k EXPR]
                              [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from contextlib import ExitStack
from pathlib import Path

from conformance.emulator_server.process import EmulatorProcess


def _run(argv: list[str]) -> tuple[float, int, str]:
    """The CLI in a process of its own: its wall time, exit status and output."""
    began = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", "conformance.cli", *argv],
                          capture_output=True, text=True)  # fmt: skip
    return time.monotonic() - began, proc.returncode, proc.stdout + proc.stderr


def _bus(folder: Path) -> str:
    """A DUT's bus time from its verdicts.json."""
    try:
        run = json.loads((folder / "verdicts.json").read_text(encoding="utf-8"))["run"]
    except (OSError, ValueError, KeyError):
        return "no verdicts.json"
    bus = run.get("bus") or {}
    return (f"bus lower bound {bus.get('bus_lower_bound_s', 0):.1f} s, on the link "
            f"{bus.get('wall_s') or bus.get('bus_span_s') or 0:.1f} s, "
            f"efficiency {bus.get('efficiency') or 0:.2f}")  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--duts", type=int, default=3, help="emulators in the rack (default 3)")
    p.add_argument("--faults", default="wrong-crc", help="the last emulator's faults ('' none)")
    p.add_argument("--profile", default="production", help="the selection (default production)")
    p.add_argument("-k", dest="keyword", help="a -k selection instead of the profile")
    p.add_argument("--keep", help="write the reports here instead of a temporary folder")
    args = p.parse_args(argv)
    out = Path(args.keep or tempfile.mkdtemp(prefix="sdi12-rack-bench-"))
    selection = ["-k", args.keyword] if args.keyword else ["--profile", args.profile]
    selection += ["--plan", "never"]
    with ExitStack() as stack:
        emulators = [
            stack.enter_context(EmulatorProcess(
                *(["--faults", args.faults] if args.faults and i == args.duts - 1 else [])
            ))
            for i in range(args.duts)
        ]  # fmt: skip
        alone = []
        for i, emulator in enumerate(emulators, 1):
            folder = out / f"alone-{i}"
            wall, code, text = _run(["--port", emulator.url, *selection,
                                     "--report-dir", str(folder)])  # fmt: skip
            alone.append(wall)
            print(f"alone  DUT {i}: {wall:6.1f} s wall, exit {code}; {_bus(folder)}")
        ports = [arg for e in emulators for arg in ("--port", e.url)]
        rack = out / "rack"
        wall, code, text = _run([*ports, *selection, "--report-dir", str(rack)])
    rows = json.loads((rack / "rack.json").read_text(encoding="utf-8"))["duts"]
    for i, row in enumerate(rows, 1):
        folder = rack / row["folder"] if row["folder"] else rack
        print(f"rack   DUT {i}: {row['wall_s'] or 0:6.1f} s in its worker, exit "
              f"{row['exit_code']}; {_bus(folder)}")  # fmt: skip
    slowest = max(alone)
    print(
        f"rack of {args.duts}: {wall:.1f} s wall, exit {code}; slowest alone {slowest:.1f} s; "
        f"ratio {wall / slowest:.2f} (target <= 1.2); one after another {sum(alone):.1f} s"
    )
    print(f"reports: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
