"""Issue 22's figures for two checkouts side by side, in one run, as ratios.

Run: ``python benchmarks/compare.py OLD NEW [--runs N] [--only FIGURE ...] [--minutes M]
[--capture PATH]``,
OLD and NEW folders holding checkouts (``git worktree add`` or ``git archive`` of a commit).
Every figure is one fresh child process per measurement, started the way a user starts it
(``python -m conformance.cli ...`` with ``PYTHONPATH`` the tree, bytecode caching on as in
CI); the trees take turns, so load that drifts during the benchmark weighs on both alike.
Prints each measurement, then per figure the median of each tree and NEW's speed-up over OLD
(OLD / NEW: above 1 is faster). The figures:

- ``sim``: the whole ``sdi12-conform --port sim`` process (wall; issue 22's 1.0 s target);
- ``wrong-crc``: the same against ``sim://?faults=wrong-crc``, the costliest fault row;
- ``exec-c``: the ``exec:`` C example (examples/c/sensor_harness.c built against each tree's
  kit header; issue 22's 1.5 s target);
- ``kit``: the kit's Arduino sensor sketch, a whole run with the build cached;
- ``matrix``: ``sdi12-conform matrix --through-capture`` over a fixed sample of faults, one
  job (CPU, given per fault: issue 22's budget is 60 s for 121 faults);
- ``capture``: ``sdi12-conform judge`` of a generated capture of a busy bus (``--minutes``,
  default 10; wall and peak memory; issue 22's target is 30 s for an hour).

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
from collections.abc import Callable
from pathlib import Path

#: faults of several kinds (protocol, CRC with retries, timing, metadata), in the capture sample
MATRIX_SAMPLE = (
    "wrong-crc", "response-too-late", "inter-char-gap", "d0-empty", "no-service-request"
)  # fmt: skip

#: runs the command given after it, then prints its wall time, CPU and peak memory as JSON
#: (a wrapper per measurement, so the peak is that command's alone)
MEASURE = (
    "import json, resource, subprocess, sys, time\n"
    "started = time.perf_counter()\n"
    "done = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
    "wall = time.perf_counter() - started\n"
    "use = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
    "print(json.dumps({'wall': wall, 'cpu': use.ru_utime + use.ru_stime,\n"
    "    'peak_mb': use.ru_maxrss / 1024, 'code': done.returncode,\n"
    "    'tail': (done.stdout + done.stderr)[-400:]}))\n"
)


def measure(tree: Path, argv: list[str], work: Path) -> dict:
    """One child process of ``argv`` with the tree's package first on the path."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    done = subprocess.run(
        [sys.executable, "-c", MEASURE, *argv], cwd=work, env=env,
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "conformance.cli", *args]


def build_exec_example(tree: Path, work: Path) -> Path:
    """The README's C sensor harness, compiled against this tree's kit header."""
    out = work / "sensor_harness"
    c = tree / "examples" / "c"
    subprocess.run(
        ["cc", "-O2", "-I", str(tree / "conformance" / "kit" / "c"), "-o", str(out),
         str(c / "sensor_harness.c"), str(c / "tiny_sensor.c")],
        check=True,
    )  # fmt: skip
    return out


def figures(
    tree: Path, work: Path, minutes: float, made: Path | None = None
) -> dict[str, Callable[[], list[str]]]:
    """Each figure's command for ``tree`` (built lazily: only the figures asked for);
    ``made``: the capture the ``capture`` figure judges (else one of ``minutes`` is made)."""
    reports = str(work / "reports")

    def exec_c() -> list[str]:
        harness = work / "sensor_harness"
        if not harness.exists():
            build_exec_example(tree, work)
        declaration = str(tree / "examples" / "c" / "tiny_sensor.toml")
        return cli("--port", f"exec:{harness}", "--declaration", declaration,
                   "--report-dir", reports)  # fmt: skip

    def kit() -> list[str]:
        sketch = tree / "examples" / "arduino"
        library = sketch / "libraries" / "TinySDI12"
        return cli("kit", "arduino", str(sketch / "sdi12_sensor"),
                   "--lib", str(library), "--report-dir", reports)  # fmt: skip

    def capture() -> list[str]:
        judged = made if made is not None else capture_file(work.parent, minutes)
        return cli("judge", str(judged), "--report-dir", reports)

    return {
        "sim": lambda: cli("--port", "sim", "--report-dir", reports),
        "wrong-crc": lambda: cli("--port", "sim://?faults=wrong-crc", "--report-dir", reports),
        "exec-c": exec_c,
        "kit": kit,
        "matrix": lambda: cli(
            "matrix", "--through-capture", "--jobs", "1", "--faults", ",".join(MATRIX_SAMPLE)
        ),  # fmt: skip
        "capture": capture,
    }


def capture_file(work: Path, minutes: float) -> Path:
    """One busy-bus capture both trees judge (made once, by the benchmark in this checkout)."""
    path = work / f"busy-{minutes:g}min.sr"
    if not path.exists():
        here = Path(__file__).with_name("capture_decode.py")
        subprocess.run(
            [sys.executable, str(here), "--minutes", str(minutes), "--keep", str(path)],
            check=True, capture_output=True,
        )  # fmt: skip
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--runs", type=int, default=3, help="measurements per tree and figure")
    parser.add_argument("--only", nargs="+", metavar="FIGURE", help="these figures only")
    parser.add_argument("--minutes", type=float, default=10.0, help="capture length")
    parser.add_argument(
        "--capture", type=Path, help="judge this capture (one made before: not made again)"
    )
    args = parser.parse_args(argv)
    trees = [args.old.resolve(), args.new.resolve()]
    with tempfile.TemporaryDirectory(prefix="sdi12-compare-") as tmp:
        works = {tree: Path(tmp) / f"tree{n}" for n, tree in enumerate(trees)}
        for work in works.values():
            work.mkdir()
        made = args.capture.resolve() if args.capture is not None else None
        per_tree = {tree: figures(tree, works[tree], args.minutes, made) for tree in trees}
        names = args.only or list(per_tree[trees[0]])
        unknown = sorted(set(names) - set(per_tree[trees[0]]))
        if unknown:
            parser.error(f"unknown figure(s) {unknown}; known: {list(per_tree[trees[0]])}")
        table = [compare_one(name, trees, per_tree, works, args.runs) for name in names]
    print()
    for line in table:
        print(line)
    return 0


def compare_one(name: str, trees: list[Path], per_tree: dict, works: dict, runs: int) -> str:
    """Measure one figure ``runs`` times per tree, taking turns (plus one warm-up each, which
    fills the bytecode and build caches); return its summary line."""
    found: dict[Path, list[dict]] = {tree: [] for tree in trees}
    for n in range(runs + 1):
        for tree in trees:
            shutil.rmtree(works[tree] / "reports", ignore_errors=True)
            got = measure(tree, per_tree[tree][name](), works[tree])
            if n:  # the first round warms up
                found[tree].append(got)
            print(
                f"{name} {'warm-up' if not n else f'run {n}'} {tree}: {got['wall']:.2f} s wall, "
                f"{got['cpu']:.2f} s CPU, {got['peak_mb']:.0f} MB, exit {got['code']}",
                flush=True,
            )
    old, new = (
        {k: statistics.median(g[k] for g in found[tree]) for k in ("wall", "cpu", "peak_mb")}
        for tree in trees
    )
    scale = f" ({new['cpu'] / len(MATRIX_SAMPLE):.2f} s CPU a fault)" if name == "matrix" else ""
    return (
        f"{name:10s} old {old['wall']:7.2f} s wall {old['cpu']:7.2f} s CPU {old['peak_mb']:5.0f} MB"
        f" | new {new['wall']:7.2f} s wall {new['cpu']:7.2f} s CPU {new['peak_mb']:5.0f} MB"
        f" | {old['wall'] / new['wall']:.2f}x wall, {old['cpu'] / new['cpu']:.2f}x CPU{scale}"
    )


if __name__ == "__main__":
    sys.exit(main())
