"""Wall time of the full sensor suite against the built-in simulated sensor.

Run: ``python benchmarks/sensor_suite_time.py [--runs N]``. Prints each run's seconds, the
median, the number of cases and of bus events, and the verdict. A benchmark, not a test: the
figure depends on the machine (issue target: under 20 s on a 2-core machine).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from conformance.conduct import conduct
from conformance.run import RunOptions


def one_run() -> tuple[float, dict, int]:
    with tempfile.TemporaryDirectory(prefix="sdi12-bench-") as tmp:
        started = time.perf_counter()
        result = conduct(RunOptions(report_dir=tmp), rootdir=tmp)
        elapsed = time.perf_counter() - started
        data = result.document
        assert data is not None
        events = sum(1 for _ in (Path(tmp) / "transcript.jsonl").open(encoding="utf-8"))
    return elapsed, data, events


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    times = []
    for n in range(runs):
        elapsed, data, events = one_run()
        times.append(elapsed)
        print(
            f"run {n + 1}: {elapsed:.2f} s, {len(data['tests'])} cases, {events} bus events, "
            f"{data['summary']['verdict']}"
        )
    print(f"median {statistics.median(times):.2f} s over {runs} run(s) (full sensor suite, sim)")


if __name__ == "__main__":
    main()
