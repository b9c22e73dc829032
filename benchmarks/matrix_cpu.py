"""CPU of the fault matrices, side by side for two or more checkouts (issue 22).

Run: ``python benchmarks/matrix_cpu.py [--what sensor|combinations] [--every K] TREE [TREE ...]``,
each TREE a folder holding a checkout (``git worktree``, or a read-only unpacked tree: its
bytecode then goes to a cache folder of its own). Each tree gets one fresh process (bytecode
caching on, as in CI), and the trees' processes run at the same time, so a machine whose load
drifts weighs on all alike. Each process makes the rows one after the other in itself
(``processes=1``: no pool, so the CPU is the rows' own and ``time.process_time`` sees all of
it) and prints one JSON line: rows, how many came out exact (clean), total CPU, and each
row's CPU.

- ``--what sensor``: every single-sensor fault (or every K-th of the sorted list), live and each
  judged through its capture (``roundtrip.row_through_capture``, as
  ``SDI12_MATRIX_CAPTURE=all`` and ``sdi12-conform matrix --through-capture`` do);
- ``--what combinations``: CI's combinations (``combinations.CI_COMBINATIONS``: 27 pairs,
  9 triples and the REGRESSIONS), each a run checked against its members.

Prints each tree's line, then the CPU ratio of every tree to the first. A benchmark, not a
test: the figures depend on the machine, the ratios much less.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

from tree_process import start_in_tree

ONE_TREE = r"""
import json, sys, time
what, every = sys.argv[1], int(sys.argv[2])
cpu = []
if what == "sensor":
    from conformance.emulator import FAULTS
    from conformance.matrices.roundtrip import row_through_capture
    from conformance.matrices.sensor_matrix import fault_matrix
    names = sorted(n for n, f in FAULTS.items() if not f.bus)[::every]
    make, good = row_through_capture, (lambda row: row.exact)
    def run(progress):
        return fault_matrix(names, processes=1, progress=progress, row=make)
else:
    from conformance.matrices.combinations import CI_COMBINATIONS, combination_matrix
    combos = list(CI_COMBINATIONS)[::every]
    good = lambda row: row.clean
    def run(progress):
        return combination_matrix(combos, processes=1, progress=progress)
last = [time.process_time()]
def progress(done, total, row):
    now = time.process_time()
    cpu.append(round(now - last[0], 3))
    last[0] = now
started = time.process_time()
rows = run(progress)
print(json.dumps({
    "rows": len(rows), "good": sum(map(good, rows)),
    "bad": [row.explain() for row in rows if not good(row)],
    "cpu_s": round(time.process_time() - started, 2), "row_cpu_s": cpu,
}))
"""


def start(tree: Path, what: str, every: int, cache: Path) -> subprocess.Popen:
    return start_in_tree(
        tree, ONE_TREE, [what, str(every)], cache, cwd=tree, drop_env=["SDI12_MATRIX_CAPTURE"]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--what", choices=("sensor", "combinations"), default="sensor")
    parser.add_argument(
        "--every", type=int, default=1, help="every K-th row only (a fixed subset: 1 in K)"
    )
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="sdi12-pyc-") as cache:
        procs = [start(t.resolve(), args.what, args.every, Path(cache)) for t in args.trees]
        results = [json.loads(p.communicate()[0].strip().splitlines()[-1]) for p in procs]
    for tree, found in zip(args.trees, results, strict=True):
        print(json.dumps({"tree": str(tree), "what": args.what} | found))
    first = results[0]["cpu_s"]
    good = "exact" if args.what == "sensor" else "clean"
    for tree, found in zip(args.trees, results, strict=True):
        print(
            f"{tree}: {found['good']}/{found['rows']} {good}, "
            f"{found['cpu_s']:.1f} s CPU, ratio {found['cpu_s'] / first:.3f}"
        )


if __name__ == "__main__":
    main()
