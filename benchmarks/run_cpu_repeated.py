"""CPU of a simulated run repeated in one process, side by side for two or more checkouts
(issue 22: the fault matrices, the combinations and CI run many suites per process, so the
figure that multiplies is a run after the first, with the imports and pytest's start behind).

Run: ``python benchmarks/run_cpu_repeated.py [--runs N] [--port PORT ...] TREE [TREE ...]``,
each TREE a folder holding a checkout (``git worktree``, or a read-only unpacked tree: its
bytecode then goes to a cache folder of its own). Each tree gets one fresh process per port
(bytecode caching on, as in CI), the trees' processes running at the same time so a machine
whose load drifts weighs on all alike; each makes one warm-up run then ``N`` measured ones
(``conduct.run_into``, reports and all) and gives their ``time.process_time``. Prints each
tree's runs, the median and its ratio to the first tree's (above 1: faster). A benchmark,
not a test: the figures depend on the machine, the ratios much less.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile
from pathlib import Path

from tree_process import start_in_tree

REPEATED = r"""
import json, sys, tempfile, time
from pathlib import Path
from conformance.conduct import run_into
port, runs = sys.argv[1], int(sys.argv[2])
cpu = []
with tempfile.TemporaryDirectory(prefix="sdi12-repeat-") as folder:
    for n in range(runs + 1):  # the first warms up (imports, pytest's start)
        started = time.process_time()
        document = run_into(Path(folder) / str(n), port)
        if n:
            cpu.append(time.process_time() - started)
print(json.dumps({"cpu": cpu, "verdict": document["summary"]["verdict"]}))
"""


def start(tree: Path, port: str, runs: int, cache: Path) -> subprocess.Popen:
    return start_in_tree(tree, REPEATED, [port, str(runs)], cache, tempfile.gettempdir())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--port", action="append", dest="ports")
    args = parser.parse_args()
    trees = [tree.resolve() for tree in args.trees]
    with tempfile.TemporaryDirectory(prefix="sdi12-pyc-") as cache:
        for port in args.ports or ["sim", "sim://?faults=wrong-crc"]:
            procs = [start(tree, port, args.runs, Path(cache)) for tree in trees]
            found = [json.loads(p.communicate()[0].strip().splitlines()[-1]) for p in procs]
            first = statistics.median(found[0]["cpu"])
            for tree, one in zip(trees, found, strict=True):
                median = statistics.median(one["cpu"])
                runs = " ".join(f"{c:.2f}" for c in one["cpu"])
                print(
                    f"{port} {tree}: median {median:.3f} s CPU ({runs}), {one['verdict']}, "
                    f"{first / median:.2f}x the first"
                )


if __name__ == "__main__":
    main()
