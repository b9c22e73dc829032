"""CPU of one simulated run, side by side for two checkouts (issue 22).

Run: ``python benchmarks/run_cpu.py [--runs N] [--cli] [--port PORT ...] TREE [TREE ...]``, each
TREE a folder holding a checkout (``git worktree`` or ``git archive`` of an older commit).
Each run is one fresh process (bytecode caching on, as in CI) timing
``conformance.conduct.run_once(PORT)`` with ``time.process_time``; the trees take turns, so a
machine whose load drifts weighs on both alike. ``--cli`` times the whole
``python -m conformance.cli --port PORT`` process instead (wall and CPU, HTML included).
Prints every run, then per port the median CPU of each tree and its ratio to the first
tree's. A benchmark, not a test: the figures
depend on the machine, the ratios much less.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ONE_RUN = (
    "import json, sys, time\n"
    "try:\n"
    "    from conformance.conduct import run_once\n"
    "except ImportError:  # a tree from before issue 21\n"
    "    from conformance.matrix import run_once\n"
    "started = time.process_time()\n"
    "data = run_once(sys.argv[1])\n"
    "print(json.dumps({'cpu': time.process_time() - started,"
    " 'verdict': data['summary']['verdict']}))\n"
)


def one_run(tree: Path, port: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    done = subprocess.run(
        [sys.executable, "-c", ONE_RUN, port],
        cwd=tree, env=env, capture_output=True, text=True, check=True,
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def one_cli_run(tree: Path, port: str) -> dict:
    """The whole ``sdi12-conform --port PORT`` process as a user starts it (interpreter,
    imports, the run, all four reports, the console summary): its wall time and CPU."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    with tempfile.TemporaryDirectory(prefix="sdi12-bench-") as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-m", "conformance.cli", "--port", port, "--report-dir", tmp],
            cwd=tree, env=env, capture_output=True, text=True,
        )  # fmt: skip
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    verdict = next((ln.split()[-1] for ln in done.stdout.splitlines() if "verdict:" in ln), "?")
    return {"cpu": cpu, "wall": wall, "verdict": verdict}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--port", action="append", dest="ports")
    parser.add_argument(
        "--cli", action="store_true", help="time the whole CLI process (wall and CPU)"
    )
    args = parser.parse_args()
    ports = args.ports or ["sim", "sim://?faults=wrong-crc"]
    run = one_cli_run if args.cli else one_run
    for port in ports:
        cpu: dict[Path, list[float]] = {tree: [] for tree in args.trees}
        wall: dict[Path, list[float]] = {tree: [] for tree in args.trees}
        for n in range(args.runs):
            for tree in args.trees:
                found = run(tree, port)
                cpu[tree].append(found["cpu"])
                wall[tree].append(found.get("wall", 0.0))
                shown = f", {found['wall']:.2f} s wall" if "wall" in found else ""
                print(
                    f"{port} run {n + 1} {tree}: {found['cpu']:.2f} s CPU{shown}, "
                    f"{found['verdict']}"
                )
        first = statistics.median(cpu[args.trees[0]])
        for tree in args.trees:
            median = statistics.median(cpu[tree])
            shown = f", {statistics.median(wall[tree]):.2f} s wall" if args.cli else ""
            print(
                f"{port}: {tree} median {median:.2f} s CPU{shown}, {first / median:.2f}x the first"
            )


if __name__ == "__main__":
    main()
