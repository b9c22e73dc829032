"""Where the tests find the checkout and the shared ground truth, from any folder depth."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

TESTS = Path(__file__).resolve().parents[1]  # tests/
ROOT = TESTS.parent  # the checkout
SHARED = ROOT.parent / "shared"  # ../shared: the spec texts, requirements.md, captures
BENCHMARKS = ROOT / "benchmarks"  # the scripts that measure the tool, not a package


def benchmark(name: str) -> ModuleType:
    """``benchmarks/<name>.py`` loaded as a module (``<name>_bench``; in ``sys.modules``
    while it runs, so its dataclasses find their module): the tests that read a benchmark's
    own traffic (the busy bus, the measuring bus) or check its arithmetic."""
    spec = importlib.util.spec_from_file_location(f"{name}_bench", BENCHMARKS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module
