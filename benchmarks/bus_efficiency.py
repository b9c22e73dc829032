"""Bus efficiency of the sensor suite on a real-time link.

Serves the reference emulator over RFC 2217 on loopback (``sdi12-conform emulate`` in a child
process), runs the full sensor suite against it with the CLI, and prints what
``verdicts.json`` records under ``run.bus``: the bus-time lower bound (what any recorder
would need for the same exchanges: frames, breaks, the marking after them, the sensor's own
delays and announced measurement times) next to the wall time the run took, and their ratio.

    python benchmarks/bus_efficiency.py [-k EXPR] [--faults NAME,...] [--keep DIR]

Takes about as long as the suite's bus time (roughly four minutes for every case).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from conformance.emulator_server.process import EmulatorProcess


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("-k", dest="keyword", help="only cases matching this expression")
    p.add_argument("--faults", default="", help="emulator faults (default: clean)")
    p.add_argument("--keep", help="write the reports here instead of a temporary folder")
    args = p.parse_args(argv)
    out = Path(args.keep or tempfile.mkdtemp(prefix="sdi12-bus-"))
    extra = ["--faults", args.faults] if args.faults else []
    with EmulatorProcess(*extra) as emulator:
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
        started = time.monotonic()
        proc = subprocess.run(command, capture_output=True, text=True)
        process_s = time.monotonic() - started
    verdicts = out / "verdicts.json"
    if not verdicts.exists():
        print(proc.stdout + proc.stderr)
        return 1
    data = json.loads(verdicts.read_text())
    bus = data["run"]["bus"]
    print(f"suite verdict        {data['summary']['verdict']} (exit {proc.returncode})")
    print(f"frames / breaks      {bus['frames']} / {bus['breaks']}")
    print(f"bus-time lower bound {bus['bus_lower_bound_s']:.1f} s")
    print(f"wall time (link)     {bus['wall_s']:.1f} s")
    print(f"efficiency           {bus['efficiency']:.2f} (lower bound / wall time)")
    print(f"whole process        {process_s:.1f} s (pytest start-up and reports included)")
    print(f"reports              {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
