"""The full sensor suite over RFC 2217 against the emulator behind each bench model.

For every model (echo, USB latency batches, jitter, an RTS-switched driver, echo with CPU
burners beside the run) it serves the clean reference emulator with ``sdi12-conform emulate``,
runs ``sdi12-conform --port rfc2217://...`` over it, and prints one Markdown row: the overall
verdict, FAIL/WARN counts, how many section 7 timing requirements got a definite verdict
(PASS or FAIL), and the uncertainty the run measured. This is the README's bench table.

    python benchmarks/bench_models.py                # every model, 2 at a time (~20 min)
    python benchmarks/bench_models.py echo usb1-echo # some of them
    python benchmarks/bench_models.py --runs 5 --burners 2   # the acceptance run (~95 min)

``--runs N`` repeats every model N times and ``--burners K`` keeps K CPU burners busy beside the
whole benchmark (on top of a model's own). With ``--runs`` above 1 it prints one row per model:
how many of its runs were clean (no FAIL, no WARN), the verdicts seen, the rules that ever
FAILed or WARNed and the spread of what the runs decided and measured.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from conformance.emulator_server.process import EmulatorProcess

#: section 7 timing requirements the sensor role judges
TIMING = (
    "R-7.0-01",
    "R-7.0-03",
    "R-7.0-04",
    "R-7.0-05",
    "R-7.0-07",
    "R-7.0-09",
    "R-7.0-10",
    "R-7.0-12",
    "R-7.0-14",
    "R-7.0-15",
    "R-7.0-16",
    "R-7.1-02",
)


@dataclass(frozen=True)
class Model:
    name: str
    what: str
    emulate: tuple[str, ...]
    tool: tuple[str, ...] = ()
    burners: int = 0


MODELS = (
    Model("ideal", "ideal interface, no echo", ()),
    Model("echo", "echoing interface", ("--echo",)),
    Model("usb1-echo", "echo, USB latency timer 1 ms", ("--echo", "--usb-latency", "1")),
    Model("usb16-echo", "echo, USB latency timer 16 ms", ("--echo", "--usb-latency", "16")),
    Model("usb1", "USB latency timer 1 ms, no echo", ("--usb-latency", "1")),
    Model("jitter-echo", "echo, 0..2 ms jitter", ("--echo", "--jitter", "2")),
    Model("rts", "RTS-switched driver", ("--require-rts",), ("--direction", "rts")),
    Model("echo-burners", "echo, two CPU burners beside", ("--echo",), burners=2),
)


def burner() -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", "while True: pass"])


def run(model: Model, out: Path) -> dict:
    burners = [burner() for _ in range(model.burners)]
    emulator = EmulatorProcess(*model.emulate)
    started = time.monotonic()
    try:
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "conformance.cli",
                "--port",
                emulator.url,
                "--report-dir",
                str(out),
                *model.tool,
            ],
            capture_output=True,
            text=True,
            timeout=1500,
        )
    finally:
        emulator.stop()
        for b in burners:
            b.kill()
            b.wait()
    data = json.loads((out / "verdicts.json").read_text())
    verdicts = {r["id"]: r["verdict"] for r in data["requirements"]}
    link = data["run"]["link"]
    timing = link.get("bench", {}).get("timing", {})
    return {
        "model": model,
        "exit": proc.returncode,
        "wall_s": time.monotonic() - started,
        "verdict": data["summary"]["verdict"],
        "fail": sorted(r for r, v in verdicts.items() if v == "FAIL"),
        "warn": sorted(r for r, v in verdicts.items() if v == "WARN"),
        "definite": sorted(r for r in TIMING if verdicts.get(r) in ("PASS", "FAIL")),
        "uncertainty_ms": link["timing_uncertainty_ms"],
        "worst_ms": max(
            (timing.get(k, {}).get("worst_ms", 0.0) for k in ("echo_spread", "artefacts")),
            default=0.0,
        ),
        "emulator": emulator.log[-1] if emulator.log else "",
    }


def row(r: dict) -> str:
    m = r["model"]
    fails = " ".join(r["fail"] + r["warn"]) or "none"
    decided = ", ".join(x.removeprefix("R-") for x in r["definite"]) or "none"
    return (
        f"| {m.what} | {r['verdict']} | {fails} | {len(r['definite'])}/{len(TIMING)} "
        f"({decided}) | ±{r['uncertainty_ms']:.2f} ms (worst {r['worst_ms']:.2f}) | "
        f"{r['wall_s']:.0f} s |"
    )


def repeated_row(model: Model, results: list[dict]) -> str:
    """One Markdown row summarising every run of ``model`` (the acceptance table)."""
    clean = sum(1 for r in results if not r["fail"] and not r["warn"])
    verdicts = ", ".join(sorted({r["verdict"] for r in results}))
    flagged = sorted({x for r in results for x in r["fail"] + r["warn"]})
    decided = [len(r["definite"]) for r in results]
    unc = [r["uncertainty_ms"] for r in results]
    walls = [r["wall_s"] for r in results]
    return (
        f"| {model.what} | {clean}/{len(results)} | {verdicts} | {' '.join(flagged) or 'none'} | "
        f"{min(decided)}-{max(decided)}/{len(TIMING)} | "
        f"±{min(unc):.2f}-{max(unc):.2f} ms | {min(walls):.0f}-{max(walls):.0f} s |"
    )


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", help="model names (default: all)")
    parser.add_argument("--runs", type=int, default=1, help="runs per model")
    parser.add_argument("--burners", type=int, default=0, help="CPU burners beside everything")
    parser.add_argument("--parallel", type=int, default=2, help="runs at a time")
    parser.add_argument("--keep", type=Path, help="keep every run's report folder here")
    args = parser.parse_args(argv)
    chosen = [m for m in MODELS if not args.models or m.name in args.models]
    if args.runs > 1 and not args.models:
        # the burner model is the acceptance run's own condition when --burners is given
        chosen = [m for m in chosen if not (args.burners and m.burners)]
    jobs = [(m, i) for i in range(args.runs) for m in chosen]
    burners = [burner() for _ in range(args.burners)]
    try:
        with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.parallel) as pool:
            root = args.keep or Path(tmp)

            def one(job: tuple[Model, int]) -> dict:
                m, i = job
                r = run(m, root / f"{m.name}-{i + 1}")
                flagged = " ".join(r["fail"] + r["warn"]) or "clean"
                line = f"{m.name} run {i + 1}: {r['verdict']} {flagged} {r['wall_s']:.0f} s"
                print(line, file=sys.stderr, flush=True)
                return r

            results = list(pool.map(one, jobs))
    finally:
        for b in burners:
            b.kill()
            b.wait()
    if args.runs > 1:
        print(
            "| bench model | clean runs | verdicts | ever FAIL/WARN | section 7 decided "
            "| measured | wall |"
        )
        print("|---|---|---|---|---|---|---|")
        for m in chosen:
            print(repeated_row(m, [r for r in results if r["model"] is m]))
    else:
        print("| bench model | verdict | FAIL/WARN | section 7 timing decided | measured | wall |")
        print("|---|---|---|---|---|---|")
        for r in results:
            print(row(r))
    for r in results:
        print(f"{r['model'].name}: emulator {r['emulator']}", file=sys.stderr)
    return 0 if all(not r["fail"] and not r["warn"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
