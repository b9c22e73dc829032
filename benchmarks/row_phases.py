"""Where a fault-matrix row's CPU goes, phase by phase, side by side for one or more checkouts
(issue 22).

Run: ``python benchmarks/row_phases.py [--every K] TREE [TREE ...]`` (from outside any
checkout). Each TREE gets one fresh process (as ``matrix_cpu.py``: bytecode caching on,
the trees' processes at the same time), which makes every K-th single-sensor fault's row
through its capture (``roundtrip.row_through_capture``, what ``matrix_cpu.py`` and
``sdi12-conform matrix --through-capture`` make), one warm-up row first, and splits each
row's ``time.process_time`` into:

- ``live.session``, ``replay.session``: the pytest session's own fixed work (argument
  parsing, plugin registration, configure, collection, the session's end, freeing the
  run), i.e. the session less its run-test loop;
- ``live.per_case``, ``replay.per_case``: pytest's per-case work (the runtest protocol's
  hooks and reports) less the cases' setup and calls;
- ``live.setup``, ``replay.setup``: the cases' fixtures (opening the link, discovery);
- ``live.cases``, ``replay.cases``: the case functions themselves (stimulus and judging);
- ``export``: the run's events to the held ``.sr`` capture; ``plan``: its decode and the
  replay's options (``offline.judge.plan``);
- ``rest``: the row less all of those (events read back, verdicts compared, folders; in a
  tree that judges a batch of runs in one pytest session, ``conformance.many_runs``, as the
  matrices do, that session's start and end, shared by the rows; the rows are then made by
  ``sensor_matrix.run_rows`` as the matrix makes them, with its collector pacing).

In such a tree the rows are made in one session as ``fault_matrix`` makes a batch, and a
run's ``session`` is what its run costs outside the items' protocol (its records, report
folder, finish).

and the cases that cost most (both halves together). Figures are ms of CPU per row. A
benchmark, not a test: the instrumentation (a pytest plugin and three wrapped functions)
costs a little itself, the same in every tree.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

from tree_process import start_in_tree

ONE_TREE = r"""
import json, sys, time
from pathlib import Path
import pytest
import conformance.capture.export as export_module
import conformance.matrices.roundtrip as roundtrip
import conformance.matrices.sensor_matrix as sensor_matrix
import conformance.offline.judge as judge_module
from conformance.emulator import FAULTS

every = int(sys.argv[1])
acc, cases, now = {}, {}, time.process_time

def add(key, value):
    acc[key] = acc.get(key, 0.0) + value

class Phases:
    def __init__(self):
        self.t = {"setup": 0.0, "calls": 0.0}
    @pytest.hookimpl(wrapper=True)
    def pytest_runtestloop(self, session):
        t = now()
        try:
            return (yield)
        finally:
            self.t["loop"] = now() - t
    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_setup(self, item):
        t = now()
        try:
            return (yield)
        finally:
            self.t["setup"] += now() - t
    @pytest.hookimpl(wrapper=True)
    def pytest_pyfunc_call(self, pyfuncitem):
        t = now()
        try:
            return (yield)
        finally:
            spent = now() - t
            self.t["calls"] += spent
            cases[pyfuncitem.name] = cases.get(pyfuncitem.name, 0.0) + spent

try:  # a tree whose matrix judges its rows' runs in one pytest session
    import conformance.many_runs as many_runs
    import conformance.many_runs_plugin as many_runs_plugin
except ImportError:
    many_runs = None
# an older tree has no such module, but an editable install's finder may supply another's
own = Path(judge_module.__file__).parents[1]
if many_runs is not None and Path(many_runs.__file__).parent != own:
    many_runs = None
shared = Phases()
if many_runs is not None:
    run_items = many_runs_plugin._run_items
    def timed_items(session):
        t = now()
        try:
            return run_items(session)
        finally:
            shared.t["loop"] = now() - t
    many_runs_plugin._run_items = timed_items

conduct = sensor_matrix.conduct
def timed_conduct(options, **kw):
    half = "live" if str(options.port).startswith("sim") else "replay"
    serving = many_runs is not None and many_runs._SERVING is not None
    if serving:  # the session's own plugin, its figures cleared for this run
        config = many_runs._SERVING.session.config
        if not config.pluginmanager.is_registered(shared):
            config.pluginmanager.register(shared)
        phases = shared
        phases.t = {"setup": 0.0, "calls": 0.0}
    else:
        phases = Phases()
        kw["plugins"] = [*kw.get("plugins", ()), phases]
    t = now()
    result = conduct(options, **kw)
    total, t = now() - t, phases.t
    add(half + ".session", total - t.get("loop", 0.0))
    add(half + ".per_case", t.get("loop", 0.0) - t["setup"] - t["calls"])
    add(half + ".setup", t["setup"])
    add(half + ".cases", t["calls"])
    return result
sensor_matrix.conduct = roundtrip.conduct = timed_conduct

def timed(module, name):
    inner = getattr(module, name)
    def wrapper(*args, **kw):
        t = now()
        try:
            return inner(*args, **kw)
        finally:
            add(name, now() - t)
    setattr(module, name, wrapper)
timed(export_module, "export_events")
timed(judge_module, "plan")

names = sorted(n for n, f in FAULTS.items() if not f.bus)[::every]
def item(name):
    spec = FAULTS[name]
    return (name, tuple(spec.violates), getattr(spec, "version", None) or "14", ())
roundtrip.row_through_capture(item(names[0]))  # imports and first-use caches: not counted
acc.clear(); cases.clear()
t = now()
def rows():
    return sum(roundtrip.row_through_capture(item(name)).exact for name in names)
if many_runs is None:
    exact = rows()
else:  # as the matrix makes its rows (run_rows: a batch's session, each row as it paces it)
    made = sensor_matrix.run_rows([item(n) for n in names], roundtrip.row_through_capture, 1,
                                  role="sensor")
    exact = sum(row.exact for row in made)
total = now() - t
n = len(names)
phases = {k.replace("export_events", "export"): round(v / n * 1e3, 1) for k, v in acc.items()}
phases["rest"] = round(total / n * 1e3 - sum(phases.values()), 1)
top = sorted(cases.items(), key=lambda kv: -kv[1])[:6]
print(json.dumps({
    "rows": n, "exact": exact, "ms_per_row": round(total / n * 1e3, 1), "phases": phases,
    "top_cases": {k: round(v / n * 1e3, 1) for k, v in top},
}))
"""

ORDER = (
    "live.session", "live.per_case", "live.setup", "live.cases", "export", "plan",
    "replay.session", "replay.per_case", "replay.setup", "replay.cases", "rest",
)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="+", type=Path)
    parser.add_argument("--every", type=int, default=4, help="every K-th fault's row (default 4)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="sdi12-pyc-") as cache:
        procs = [
            start_in_tree(
                t.resolve(),
                ONE_TREE,
                [str(args.every)],
                Path(cache),
                cwd=cache,
                drop_env=["SDI12_MATRIX_CAPTURE"],
            )
            for t in args.trees
        ]
        results = [json.loads(p.communicate()[0].strip().splitlines()[-1]) for p in procs]
    for tree, found in zip(args.trees, results, strict=True):
        print(json.dumps({"tree": str(tree)} | found))
    width = max(len(k) for k in ORDER)
    print(f"{'ms CPU per row':<{width}} " + " ".join(f"{t.name:>12}" for t in args.trees))
    for key in (*ORDER, "ms_per_row"):
        values = [r["phases"].get(key, 0.0) if key != "ms_per_row" else r[key] for r in results]
        shares = [v / r["ms_per_row"] * 100 for v, r in zip(values, results, strict=True)]
        cells = " ".join(f"{v:7.1f} {s:3.0f}%" for v, s in zip(values, shares, strict=True))
        print(f"{key:<{width}} {cells}")


if __name__ == "__main__":
    main()
