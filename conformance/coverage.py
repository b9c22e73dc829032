"""Which conformance cases cover which requirement: read from the cases' markers.

Used by `sdi12-conform list` and by the tool's own coverage test, so a requirement can never be
claimed as covered without a case that names it.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from dataclasses import dataclass

from .catalog import for_role


def case_requirements(role: str) -> dict[str, list[str]]:
    """Map requirement ID -> ``module::case`` names for the cases of ``role``."""
    package = importlib.import_module(f"testcases.{role}")
    found: dict[str, list[str]] = {}
    for info in pkgutil.iter_modules(package.__path__):
        if not info.name.startswith("test_"):
            continue
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        module_marks = getattr(module, "pytestmark", [])
        if not isinstance(module_marks, list):  # a single mark is allowed too
            module_marks = [module_marks]
        for name, obj in inspect.getmembers(module, inspect.isfunction):
            if not name.startswith("test_") or obj.__module__ != module.__name__:
                continue
            marks = list(getattr(obj, "pytestmark", [])) + [
                getattr(m, "mark", m) for m in module_marks
            ]
            for mark in marks:
                if mark.name == "requirements":
                    for rid in mark.args:
                        found.setdefault(rid, []).append(f"{info.name}::{name}")
    return found


@dataclass(frozen=True)
class CoverageRow:
    id: str
    level: str
    testable: bool
    cases: tuple[str, ...]
    reason: str
    statement: str


def coverage_rows(role: str) -> list[CoverageRow]:
    cases = case_requirements(role)
    return [
        CoverageRow(
            req.id,
            req.level,
            req.testable(role),
            tuple(cases.get(req.id, ())),
            req.untestable_reason or "",
            req.statement,
        )
        for req in for_role(role)
    ]
