"""CI's not-real-time session as a schedule: how long its module order takes on 2 cores.

A loaded machine cannot time ``.ci/test`` (its wall time is the other sessions' load), but
each test's CPU can be measured there. Two steps:

1. Measure: this file is also a pytest plugin that writes, per worker, each test's node id
   and CPU (the process's and its waited-for children's: CLI runs, compilers)::

       CI_CPU_DIR=/tmp/cpu PYTHONPATH=benchmarks python -m pytest -p ci_schedule \\
           -m 'not realtime' -n 4 --dist loadfile --no-loadscope-reorder

2. Model: ``python benchmarks/ci_schedule.py /tmp/cpu OLD_TREE NEW_TREE`` collects both
   trees' not-real-time tests and plays each tree's queue (the old one as xdist 3.8 orders
   it by default, most tests first; the new one in collection order, as ``.ci/test`` hands
   it out) on 4 workers sharing 2 cores, with the measured CPU per module, the modules that
   wait on real-time lines kept to their measured wall time, and the real-time session's CPU
   served first. It prints each order's makespan and the core-seconds left idle.

A model, not a run: it leaves out xdist's own overhead and a worker taking its next module
two tests early. For the old order it gave 584 s where CI measured 596 s (stop 36).
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

#: Modules whose wall time is mostly waiting on a line paced in real time (measured alone on
#: the shared machine, stop 37): they take at least this long whatever CPU is free.
WAIT_FLOOR_S = {
    "tests/e2e/test_hostile_devices.py": 167.0,
    "tests/e2e/test_hostile_replies.py": 94.0,
}

_rows: list[tuple[str, float]] = []


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    before = _cpu()
    yield
    _rows.append((item.nodeid, _cpu() - before))


def pytest_sessionfinish(session: pytest.Session) -> None:
    folder = os.environ.get("CI_CPU_DIR")
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if folder and worker:  # the workers run the tests; the controller has none
        Path(folder).mkdir(parents=True, exist_ok=True)
        (Path(folder) / f"cpu-{worker}-{os.getpid()}.json").write_text(json.dumps(_rows))


def module_cpu(folder: Path) -> dict[str, float]:
    """CPU seconds per test module, summed over the workers' files."""
    cpu: dict[str, float] = collections.defaultdict(float)
    for path in folder.glob("cpu-*.json"):
        for nodeid, seconds in json.loads(path.read_text()):
            cpu[nodeid.split("::", 1)[0]] += seconds
    return cpu


def collected(tree: Path) -> list[str]:
    """The module of each not-real-time test ``tree`` collects, in collection order (run
    from the tree's own folder with only it on the path)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | {"PYTHONPATH": str(tree)}
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-m", "not realtime",
         "--rootdir", str(tree), "-c", str(tree / "pyproject.toml"), str(tree / "tests")],
        capture_output=True, text=True, cwd="/tmp", env=env, check=True,
    )  # fmt: skip
    lines = [line for line in out.stdout.splitlines() if "::" in line]
    return [line.split("::", 1)[0].removeprefix(f"{tree}/") for line in lines]


def queue(modules: list[str], most_tests_first: bool) -> list[str]:
    """The work queue xdist's loadfile scheduler builds (its default sorts by test count)."""
    counts = collections.Counter(modules)
    order = list(dict.fromkeys(modules))
    return sorted(order, key=lambda m: -counts[m]) if most_tests_first else order


def makespan(
    order: list[str], cpu: dict[str, float], workers: int = 4, cores: float = 2.0,
    rt_cpu: float = 97.0, rt_wall: float = 320.0, step: float = 0.05,
) -> tuple[float, float]:  # fmt: skip
    """Seconds until the last module ends, and core-seconds left idle meanwhile."""
    waiting = collections.deque(order)
    running: dict[int, list] = {}  # worker -> [module, CPU left, earliest end]
    now = idle = 0.0

    def take(worker: int) -> None:
        if waiting:
            module = waiting.popleft()
            running[worker] = [module, cpu.get(module, 0.0), now + WAIT_FLOOR_S.get(module, 0.0)]
        else:
            running.pop(worker, None)

    for worker in range(workers):
        take(worker)
    while running:
        free = cores - (rt_cpu / rt_wall if now < rt_wall else 0.0)
        caps = {w: r[1] / (r[2] - now) if r[2] - now > step else 1.0 for w, r in running.items()}
        for i, worker in enumerate(sorted(running, key=caps.get)):
            give = min(caps[worker], free / (len(running) - i), 1.0)
            running[worker][1] -= give * step
            free -= give
        idle += max(free, 0.0) * step
        now += step
        for worker in [w for w, r in running.items() if r[1] <= 0 and now >= r[2]]:
            take(worker)
    return now, idle


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("cpu", type=Path, help="CI_CPU_DIR of a measured session")
    parser.add_argument("old", type=Path, help="the tree before (xdist's default order)")
    parser.add_argument("new", type=Path, help="the tree after (its collection order)")
    parser.add_argument(
        "--old-in-collection-order", action="store_true",
        help="play the old tree's queue in its collection order too (both trees run "
        "--no-loadscope-reorder, as .ci/test has since stop 37)",
    )  # fmt: skip
    parser.add_argument(
        "--rt-cpu", type=float, default=97.0,
        help="CPU seconds of the real-time session beside it (served first)",
    )  # fmt: skip
    args = parser.parse_args()
    cpu = module_cpu(args.cpu)
    print(f"{len(cpu)} modules, {sum(cpu.values()):.0f} s of CPU")
    started = time.monotonic()
    old_by_count = not args.old_in_collection_order
    for name, tree, by_count in (("old", args.old, old_by_count), ("new", args.new, False)):
        span, idle = makespan(queue(collected(tree), by_count), cpu, rt_cpu=args.rt_cpu)
        print(f"{name} ({tree}): {span:.0f} s, {idle:.0f} core-seconds idle")
    print(f"(modelled in {time.monotonic() - started:.0f} s)")


if __name__ == "__main__":
    main()
