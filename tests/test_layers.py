"""The shape of ``conformance/``: every module imports on its own, no import cycle, and the
layers depend one way only (a lower layer never imports a higher one).

The import graph is read from the source with ``ast`` (every ``import`` statement, including
those inside functions and under ``TYPE_CHECKING``), so a cycle hidden by a function-local
import is found here and not only at run time. A new module is placed by its package; a new
top-level module or package has to be given a layer in :data:`LAYERS` first.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.paths import ROOT

ROOT = ROOT / "conformance"

#: The layers, lowest first. A module may import its own layer and the ones before it. Names
#: are top-level packages or modules under ``conformance`` (``""`` is the package itself): a
#: folder is one layer, and a module that serves a higher layer moves to a folder of that
#: layer instead of being excepted here.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    # protocol facts and the record of the wire (sans-I/O); process plumbing (signals, exit
    # codes, atomic writes, the garbage collector's pace, dataclass code compiled once)
    (
        "wire",
        (
            "",
            "interrupts",
            "exits",
            "atomic",
            "suggest",
            "gc_pace",
            "dataclass_code",
            "protocol",
            "transcript",
            "event_store",
        ),
    ),
    # the requirements, what is declared about the DUT, what a recorder under test is asked
    # to do, and what was found
    (
        "requirements",
        (
            "catalog",
            "verdicts",
            "selection",
            "profiles",
            "results",
            "root_causes",
            "coverage",
            "declaration",
            "recorder_jobs",
        ),
    ),
    # moving characters and breaks, real and virtual; the registry of link kinds; reading and
    # writing logic-analyser captures of the line
    ("links", ("links", "capture")),
    # devices the tool simulates, hosts or plays back on a virtual-time bus (and recordings
    # standing where a link would)
    ("devices", ("sim", "emulator", "harness", "replay")),
    # a --port string opened as a link (every kind); the emulator served on a port
    ("ports", ("ports", "emulator_server")),
    # the tool's own data recorder and the judges of what it recorded
    ("judging", ("tool_recorder", "case", "judges", "view", "preconditions", "dut")),
    # the two roles, with the drivers that make a recorder under test act
    ("roles", ("sensor", "recorder")),
    # one conformance run and what starts one: options, checks, the suite, the fault matrices,
    # calibration, judging a saved run again
    (
        "run",
        (
            "run",
            "conduct",
            "many_runs",
            "offline",
            "options",
            "preflight",
            "stash",
            "suite",
            "matrices",
            "calibrate",
            "monitor",
            "whole_run",
            "report_folder",
            "kit",
        ),
    ),
    # what a run is rendered as: console, HTML, verdicts.json
    ("reports", ("reports", "run_notes")),
    # pytest's side: options, fixtures, hooks that turn findings into outcomes and reports
    ("plugin", ("plugin", "many_runs_plugin")),
    # the command line: the main command and the subcommands that render as they go
    ("cli", ("cli", "commands", "rack")),
)

LAYER_OF = {name: rank for rank, (_, names) in enumerate(LAYERS) for name in names}
LAYER_NAMES = [name for name, _ in LAYERS]


def modules() -> dict[str, Path]:
    """``conformance.links.factory`` -> its file, for every module and package."""
    found = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


MODULES = modules()


def _target(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def imports_of(module: str) -> set[str]:
    """The ``conformance`` modules ``module`` imports anywhere in its source."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _target(module, path.name == "__init__.py", node)
            names = [
                f"{base}.{alias.name}" if f"{base}.{alias.name}" in MODULES else base
                for alias in node.names
            ]
        else:
            continue
        for name in names:
            if name == "conformance" or name.startswith("conformance."):
                while name not in MODULES:  # `import conformance.x.y as z`, a missing name
                    name = name.rsplit(".", 1)[0]
                found.add(name)
    found.discard(module)
    return found


GRAPH = {module: imports_of(module) for module in MODULES}


def layer_of(module: str) -> int:
    """The rank of the layer ``module`` belongs to, by the longest name that contains it."""
    inner = module.removeprefix("conformance").removeprefix(".")
    parts = inner.split(".") if inner else []
    for n in range(len(parts), -1, -1):
        name = ".".join(parts[:n])
        if name in LAYER_OF and (n or not parts):
            return LAYER_OF[name]
    raise AssertionError(
        f"{module} belongs to no layer: add conformance.{parts[0]} to LAYERS in "
        f"{Path(__file__).name} (which layer it imports from, which layers import it)"
    )


def test_a_folder_is_one_layer():
    """Layers are named by packages and top-level modules only: no module of a package sits
    in another layer than its package (the per-module exceptions of issue 21 are gone)."""
    assert [name for _, names in LAYERS for name in names if "." in name] == []


def test_every_module_and_package_has_a_layer():
    unplaced = []
    for module in MODULES:
        try:
            layer_of(module)
        except AssertionError as exc:
            unplaced.append(str(exc))
    assert not unplaced, "\n".join(unplaced)


def test_a_new_module_is_placed_by_its_package_and_an_unknown_one_is_refused():
    assert LAYER_NAMES[layer_of("conformance.judges.some_new_judge")] == "judging"
    assert LAYER_NAMES[layer_of("conformance.recorder.harness_driver")] == "roles"
    assert LAYER_NAMES[layer_of("conformance.harness.device")] == "devices"
    assert LAYER_NAMES[layer_of("conformance")] == "wire"
    with pytest.raises(AssertionError, match="conformance.mystery to LAYERS"):
        layer_of("conformance.mystery.thing")


def test_no_module_imports_a_higher_layer():
    upward = [
        f"{module} ({LAYER_NAMES[layer_of(module)]}) imports {target} "
        f"({LAYER_NAMES[layer_of(target)]})"
        for module, targets in sorted(GRAPH.items())
        for target in sorted(targets)
        if layer_of(target) > layer_of(module)
    ]
    assert not upward, "imports against the layers:\n" + "\n".join(upward)


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as a path ``[a, b, ..., a]``, or None (iterative depth-first search)."""
    state: dict[str, int] = {}  # 1 on the current path, 2 done
    for root in sorted(graph):
        if state.get(root):
            continue
        path = [root]
        stack = [iter(sorted(graph[root]))]
        state[root] = 1
        while stack:
            nxt = next(stack[-1], None)
            if nxt is None:
                state[path.pop()] = 2
                stack.pop()
            elif state.get(nxt) == 1:
                return [*path[path.index(nxt) :], nxt]
            elif not state.get(nxt):
                state[nxt] = 1
                path.append(nxt)
                stack.append(iter(sorted(graph.get(nxt, ()))))
    return None


def test_the_cycle_finder_finds_a_cycle_hidden_anywhere():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"b"}}) == ["b", "c", "b"]


def test_no_import_cycle():
    cycle = find_cycle(GRAPH)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_the_graph_sees_function_local_imports():
    # cli imports the emulator's fault table only inside `sdi12-conform faults`
    assert "conformance.emulator" in GRAPH["conformance.cli"]
    assert "conformance.links.factory" in GRAPH["conformance.ports"]


ISOLATED = """
import importlib, sys, traceback
failed = []
for name in sys.argv[1:]:
    for loaded in [m for m in sys.modules if m == "conformance" or m.startswith("conformance.")]:
        del sys.modules[loaded]
    try:
        importlib.import_module(name)
    except BaseException:
        failed.append(name + ":\\n" + traceback.format_exc(limit=-3))
print("\\n".join(failed))
sys.exit(1 if failed else 0)
"""


@pytest.mark.slow
def test_every_module_imports_on_its_own():
    """Each module imported first, in a fresh module table (one interpreter, sys.modules
    emptied of ``conformance`` between them): an import that works only because another
    module happened to be imported first fails here."""
    names = sorted(MODULES)
    done = subprocess.run(
        [sys.executable, "-c", ISOLATED, *names],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout + done.stderr


#: The longest a function of ``conformance/`` may be (issue 21): past it, split it.
MAX_FUNCTION_LINES = 80


def test_no_function_is_over_80_lines():
    long = []
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(f"{module}.{node.name}: {lines} lines")
    assert not long, "\n".join(long)
