"""The critical path of a whole ``sdi12-conform --port sim`` process, side by side for two
checkouts (issue 22's 1.0 s target is this process's wall on a quiet 2-core machine).

Run: ``python benchmarks/critical_path.py OLD NEW [--runs N] [--port PORT]``, OLD and NEW
folders holding checkouts. Each run is one fresh process of the main command (``python -m
conformance.cli --port PORT --report-dir ...``, bytecode caching on as in CI) started through
a wrapper that notes, without changing what the process does: the parent's CPU up to its
last fork (report.html's renderer, ``reports/html_aside.py``), its CPU after it, the time it
waited for children, its minor page faults (a fork makes every page the parent writes
afterwards fault once more), and each forked child's own CPU (the last fork's child: the
page's renderer; any earlier one: a helper). The trees take turns. Prints per figure the
median of each tree and OLD / NEW (above 1: NEW is better), and the critical path's CPU:
the parent up to the last fork plus the longer of its own rest and the page child's, which
is the process's wall on a machine with an idle second core, as near as CPU figures get to
it on a shared one (where the wall is mostly other processes' load).

A benchmark, not a test: the figures depend on the machine, the ratios much less.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: run in the measured process before the main command: notes the forks, the waits and the
#: exit (argv[1]: the folder for the notes; the rest: the main command's arguments)
WRAPPER = r"""
import json, os, resource, runpy, sys, time
notes = sys.argv[1]
sys.argv = ["sdi12-conform", *sys.argv[2:]]
forks, waited = [], [0.0]
real_fork, real_waitpid, real_exit = os.fork, os.waitpid, os._exit

def faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt

def fork():
    forks.append({"cpu": time.process_time(), "faults": faults(), "at": time.perf_counter()})
    pid = real_fork()
    if pid == 0:
        started = time.process_time()
        def child_exit(code):
            with open(os.path.join(notes, f"child-{len(forks)}.json"), "w") as f:
                json.dump({"cpu": time.process_time() - started, "code": code}, f)
            real_exit(code)
        os._exit = child_exit
    return pid

def waitpid(pid, options):
    at = time.perf_counter()
    try:
        return real_waitpid(pid, options)
    finally:
        waited[0] += time.perf_counter() - at

def parent_exit(code):
    with open(os.path.join(notes, "parent.json"), "w") as f:
        json.dump({"cpu": time.process_time(), "faults": faults(), "forks": forks,
                   "waited": waited[0], "at": time.perf_counter()}, f)
    real_exit(code)

os.fork, os.waitpid, os._exit = fork, waitpid, parent_exit
runpy.run_module("conformance.cli", run_name="__main__", alter_sys=True)
"""

FIGURES = (
    ("wall", "s, the whole process"),
    ("to_last_fork", "s CPU, the parent up to its last fork"),
    ("parent_after", "s CPU, the parent after it"),
    ("page_child", "s CPU, the last fork's child (report.html)"),
    ("helpers", "s CPU, any earlier forks' children"),
    ("waited", "s, the parent waiting for children"),
    ("faults_at_fork", "minor faults of the parent up to its last fork"),
    ("critical", "s CPU, to the last fork + the longer side after it"),
)


def one_run(tree: Path, port: str, work: Path) -> dict[str, float]:
    """One measured process of the main command against ``port`` with ``tree`` first."""
    notes = work / "notes"
    shutil.rmtree(notes, ignore_errors=True)
    shutil.rmtree(work / "reports", ignore_errors=True)
    notes.mkdir(parents=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    argv = [sys.executable, "-c", WRAPPER, str(notes), "--port", port,
            "--report-dir", str(work / "reports")]  # fmt: skip
    started = time.perf_counter()
    # a faulty sim exits 1 (non-compliant): the notes are what counts, not the verdict
    subprocess.run(argv, cwd=work, env=env, stdout=subprocess.DEVNULL, check=False)
    wall = time.perf_counter() - started
    parent = json.loads((notes / "parent.json").read_text())
    forks = parent["forks"]
    # a child that was killed (a helper stopped by the parent) leaves no note: 0 s counted
    children = [
        json.loads(note.read_text())["cpu"] if note.exists() else 0.0
        for note in (notes / f"child-{n}.json" for n in range(1, len(forks) + 1))
    ]
    if not forks:  # no page child (no fork here): the parent is the whole path
        return {"wall": wall, "to_last_fork": parent["cpu"], "parent_after": 0.0,
                "page_child": 0.0, "helpers": 0.0, "waited": parent["waited"],
                "faults_at_fork": parent["faults"], "critical": parent["cpu"]}  # fmt: skip
    last = forks[-1]
    after = parent["cpu"] - last["cpu"]
    page = children[-1]
    return {
        "wall": wall,
        "to_last_fork": last["cpu"],
        "parent_after": after,
        "page_child": page,
        "helpers": sum(children[:-1]),
        "waited": parent["waited"],
        "faults_at_fork": last["faults"],
        "critical": last["cpu"] + max(after, page),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--runs", type=int, default=11, help="measured runs per tree")
    parser.add_argument("--port", default="sim")
    args = parser.parse_args(argv)
    trees = [args.old.resolve(), args.new.resolve()]
    found: dict[Path, list[dict[str, float]]] = {tree: [] for tree in trees}
    with tempfile.TemporaryDirectory(prefix="sdi12-critical-") as tmp:
        for n in range(args.runs + 1):  # the first round warms the bytecode caches up
            for i, tree in enumerate(trees):
                got = one_run(tree, args.port, Path(tmp) / f"tree{i}")
                if n:
                    found[tree].append(got)
                    print(f"run {n} {tree}: " + ", ".join(f"{k} {v:.3f}" for k, v in got.items()),
                          flush=True)  # fmt: skip
    print()
    for name, what in FIGURES:
        old, new = (statistics.median(r[name] for r in found[tree]) for tree in trees)
        ratio = f"{old / new:5.2f}x" if new else "   - "
        print(f"{name:15s} old {old:10.3f} new {new:10.3f} {ratio}  ({what})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
