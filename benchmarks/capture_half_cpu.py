"""CPU of the capture half of fault-matrix rows, side by side for two or more checkouts (issue 22).

Run: ``python benchmarks/capture_half_cpu.py [--every K] [--rounds R] TREE [TREE ...]``. A
matrix row through its capture (``roundtrip.row_through_capture``) is a live run, then the
part this measures: the run exported to .sr with the tool's TX channel, ``judge``'s plan (the
capture decoded, ``capture.jsonl`` written) and the replay run against it. Each tree gets one
fresh process (bytecode caching on, as in CI), all at the same time so the machine's load
weighs on each alike; each makes the live runs of every K-th single-sensor fault once, then
times the three phases of every one of them ``R`` times, the first round a warm-up, and
prints one JSON line: each phase's CPU (``time.process_time``) summed over the rounds after
the first, and whether every replay gave the same verdicts in every round. Then the ratio of
every tree to the first, per phase and in all. A benchmark, not a test.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

from tree_process import start_in_tree

ONE_TREE = r"""
import json, sys, tempfile, time
from dataclasses import replace
from pathlib import Path
from conformance.capture.export import export_events
from conformance.conduct import conduct, run_into
from conformance.emulator import FAULTS
from conformance.matrices.sensor_matrix import fault_port
from conformance.offline.judge import plan
from conformance.protocol.version import V14
from conformance.replay.recording import read_recording
from conformance.transcript import EventKind
every, rounds = int(sys.argv[1]), int(sys.argv[2])
names = sorted(n for n, f in FAULTS.items() if not f.bus)[::every]
work = Path(tempfile.mkdtemp(prefix="sdi12-half-"))
for name in names:
    item = (name, (), getattr(FAULTS[name], "version", None) or V14, ())
    run_into(work / name / "live", fault_port(item))
cpu = {"export": 0.0, "plan": 0.0, "replay": 0.0}
verdicts = {}
for r in range(rounds):
    for name in names:
        folder = work / name
        events = read_recording(folder / "live").events
        notes = [e for e in events if e.kind is EventKind.NOTE]
        again = folder / f"capture-{r}"
        t0 = time.process_time()
        export_events(events, str(folder / "run.sr"), "sr", tool_channel=True, notes=notes)
        t1 = time.process_time()
        found = plan([str(folder / "run.sr"), "--report-dir", str(again)])
        t2 = time.process_time()
        options = replace(found.replay, report_dir=str(again))
        doc = conduct(options, html=False, rootdir=again).document
        t3 = time.process_time()
        if r:
            cpu["export"] += t1 - t0
            cpu["plan"] += t2 - t1
            cpu["replay"] += t3 - t2
        got = [(q["id"], q["verdict"]) for q in doc["requirements"]]
        verdicts.setdefault(name, got)
        verdicts[name] = verdicts[name] if verdicts[name] == got else None
print(json.dumps({
    "rows": len(names), "rounds": rounds - 1,
    "steady": all(v is not None for v in verdicts.values()),
} | {k: round(v, 2) for k, v in cpu.items()}))
"""

PHASES = ("export", "plan", "replay")


def start(tree: Path, every: int, rounds: int, cache: Path) -> subprocess.Popen:
    return start_in_tree(tree, ONE_TREE, [str(every), str(rounds)], cache, tempfile.gettempdir())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--every", type=int, default=20, help="every K-th fault (1 in K)")
    parser.add_argument("--rounds", type=int, default=3, help="the first one a warm-up")
    args = parser.parse_args()
    if args.rounds < 2:
        parser.error("--rounds: at least 2 (the first is a warm-up)")
    with tempfile.TemporaryDirectory(prefix="sdi12-pyc-") as cache:
        procs = [start(t.resolve(), args.every, args.rounds, Path(cache)) for t in args.trees]
        results = [json.loads(p.communicate()[0].strip().splitlines()[-1]) for p in procs]
    first = results[0]
    for tree, found in zip(args.trees, results, strict=True):
        total = sum(found[k] for k in PHASES)
        ratios = ", ".join(f"{k} {found[k] / first[k]:.3f}" for k in PHASES)
        print(json.dumps({"tree": str(tree)} | found))
        print(
            f"{tree}: {found['rows']} rows x {found['rounds']} rounds, {total:.1f} s CPU, "
            f"ratio {total / sum(first[k] for k in PHASES):.3f} ({ratios})"
        )


if __name__ == "__main__":
    main()
