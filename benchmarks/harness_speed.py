"""Wall and CPU of whole ``exec:`` runs, side by side for two checkouts (issue 22).

Run: ``python benchmarks/harness_speed.py [--runs N] OLD NEW``, each a folder holding a
checkout (``/work/base``, a ``git worktree``). For each tree it first builds, with that tree's
own kit files, ``examples/c/sensor_harness.c`` (on ``conformance/kit/c/sdi12_kit.h``) and the
Arduino sensor sketch (``sdi12-conform kit arduino examples/arduino/sdi12_sensor --build-only``),
then times, the trees taking turns so that a machine whose load drifts weighs on both alike:

- ``c``: ``sdi12-conform --port exec:sensor_harness --declaration tiny_sensor.toml``;
- ``kit``: ``sdi12-conform kit arduino examples/arduino/sdi12_sensor --lib ... --declaration
  sdi12_sensor.toml`` (the build cached, as CI's second run of a sketch finds it);
- ``logger``: the same for ``examples/arduino/sdi12_logger`` in the recorder role (24 jobs,
  a harness process each).

Each run is one fresh process (bytecode caching on, as in CI); CPU is the process and the
harness it starts (``RUSAGE_CHILDREN``). Prints every run, then per case the median wall and
CPU of each tree and its ratio to the first tree's, and the verdict line (the same verdicts
are the point: a speed-up that changes one is a bug). A benchmark, not a test.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LIB = ("--lib", "examples/arduino/libraries/TinySDI12")
SKETCH = ("examples/arduino/sdi12_sensor", *LIB)
LOGGER = ("examples/arduino/sdi12_logger", *LIB)


def environment(tree: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    return env


def build(tree: Path, folder: Path) -> dict[str, list[str]]:
    """The two cases' command lines for ``tree``, their binaries built into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    binary = folder / "sensor_harness"
    c_dir = tree / "conformance" / "kit" / "c"
    sources = [str(tree / "examples" / "c" / n) for n in ("sensor_harness.c", "tiny_sensor.c")]
    subprocess.run(["cc", "-O2", f"-I{c_dir}", "-o", str(binary), *sources], check=True)
    cli = [sys.executable, "-m", "conformance.cli"]
    kit = [*cli, "kit", "arduino", *SKETCH, "--build-dir", str(folder / "kit")]
    logger = [*cli, "kit", "arduino", *LOGGER, "--build-dir", str(folder / "logger")]
    for command in (kit, logger):
        subprocess.run([*command, "--build-only"], cwd=tree, env=environment(tree), check=True,
                       capture_output=True)  # fmt: skip
    return {
        "c": [*cli, "--port", f"exec:{binary}", "--declaration", "examples/c/tiny_sensor.toml"],
        "kit": [*kit, "--declaration", "examples/arduino/sdi12_sensor/sdi12_sensor.toml"],
        "logger": [*logger, "--role", "recorder", "--declaration", "examples/c/tiny_logger.toml"],
    }


def one_run(tree: Path, argv: list[str]) -> dict:
    with tempfile.TemporaryDirectory(prefix="sdi12-bench-") as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        done = subprocess.run([*argv, "--report-dir", tmp], cwd=tree, env=environment(tree),
                              capture_output=True, text=True)  # fmt: skip
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    lines = done.stdout.splitlines()
    verdict = next((ln.split()[-1] for ln in lines if ln.startswith("verdict:")), "?")
    counts = next((ln for ln in lines if " PASS" in ln and "testable" in ln), "")
    return {"cpu": cpu, "wall": wall, "verdict": f"{verdict} ({counts.split(';')[0]})"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--case", action="append", choices=("c", "kit", "logger"), dest="cases")
    args = parser.parse_args()
    trees = [tree.resolve() for tree in args.trees]
    with tempfile.TemporaryDirectory(prefix="sdi12-harness-bench-") as tmp:
        commands = {tree: build(tree, Path(tmp) / str(i)) for i, tree in enumerate(trees)}
        for case in args.cases or ["c", "kit", "logger"]:
            found: dict[Path, list[dict]] = {tree: [] for tree in trees}
            for n in range(args.runs):
                for tree in trees:
                    run = one_run(tree, commands[tree][case])
                    found[tree].append(run)
                    print(f"{case} run {n + 1} {tree}: {run['wall']:.2f} s wall, "
                          f"{run['cpu']:.2f} s CPU, {run['verdict']}", flush=True)  # fmt: skip
            first = statistics.median(r["wall"] for r in found[trees[0]])
            first_cpu = statistics.median(r["cpu"] for r in found[trees[0]])
            for tree in trees:
                wall = statistics.median(r["wall"] for r in found[tree])
                cpu = statistics.median(r["cpu"] for r in found[tree])
                print(f"{case}: {tree} median {wall:.2f} s wall ({first / wall:.2f}x the first), "
                      f"{cpu:.2f} s CPU ({first_cpu / cpu:.2f}x)")  # fmt: skip


if __name__ == "__main__":
    main()
