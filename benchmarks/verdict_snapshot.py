"""Snapshot every sim run's verdicts.json, normalised, to compare two trees (issue 21).

A structural change must leave what the tool says unchanged: the clean sensor and recorder
sims and every faulty one give byte-identical verdicts.json apart from timestamps, durations
and the tool version. Run it from each tree and diff the folders::

    PYTHONPATH=OLD python benchmarks/verdict_snapshot.py /tmp/snap-old
    PYTHONPATH=NEW python benchmarks/verdict_snapshot.py /tmp/snap-new
    diff -r /tmp/snap-old /tmp/snap-new

``--one-session``: the sensor runs are judged a batch at a time in one pytest session
(``conformance.many_runs``, as the fault matrices judge theirs), the recorder runs each in a
session of its own: the snapshot must not change either.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

#: keys whose values change from run to run whatever the code does
VOLATILE = {
    "started",
    "finished",
    "duration_s",
    "version",
    "wall_s",
    "cpu_s",
    "transcript.jsonl",  # its hash: the transcript file carries the start time
}


def normalise(data: object) -> object:
    """``data`` with every volatile value replaced by a fixed marker."""
    if isinstance(data, dict):
        return {k: ("*" if k in VOLATILE else normalise(v)) for k, v in data.items()}
    if isinstance(data, list):
        return [normalise(v) for v in data]
    return data


def items() -> list[tuple[str, str, str]]:
    """(name, port, role) of every run: clean sims, then each sensor and recorder fault."""
    from conformance.emulator import FAULTS
    from conformance.matrices.sensor_matrix import fault_port
    from conformance.recorder.faults import RECORDER_FAULTS

    runs = [("clean-sensor", "sim", "sensor"), ("clean-recorder", "sim", "recorder")]
    for name in sorted(n for n, f in FAULTS.items() if not f.bus):  # one sensor per run
        version = getattr(FAULTS[name], "version", None) or "14"
        runs.append((f"sensor-{name}", fault_port((name, (), version, ())), "sensor"))
    runs += [
        (f"recorder-{n}", f"sim://?recorder-faults={n}", "recorder")
        for n in sorted(RECORDER_FAULTS)
    ]
    return runs


def snap(item: tuple[str, str, str], out: str) -> str:
    from conformance.conduct import run_once

    name, port, role = item
    data = normalise(run_once(port, role=role))
    Path(out, f"{name}.json").write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    return name


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--only", nargs="*", help="names (as the files are named) to run")
    parser.add_argument(
        "--one-session", action="store_true", help="sensor runs a batch at a time in one session"
    )
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    runs = [i for i in items() if not args.only or i[0] in args.only]
    from functools import partial

    from conformance.matrices.sensor_matrix import run_rows

    run_rows(
        runs,
        partial(snap, out=str(args.out)),
        args.processes,
        lambda done, total, name: print(f"{done}/{total} {name}", file=sys.stderr),
        **({"role": "sensor"} if args.one_session else {}),
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
