"""The rack's own outputs over its DUTs' runs: the exit status, ``rack.json``, ``junit.xml``
with one ``<testsuite>`` per DUT, and a self-contained ``index.html``.

Each is made from the rows :func:`dut_row` builds out of a worker's result; each DUT's own
four reports stay in its folder, untouched.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..atomic import atomic_path
from ..exits import (
    EXIT_COMPLIANT,
    EXIT_INCOMPLETE,
    EXIT_INTERNAL,
    EXIT_NO_DEVICE,
    EXIT_NON_COMPLIANT,
    EXIT_USAGE,
)

SCHEMA = "sdi12-conform/rack/1"

#: worst first. Statuses that say a DUT's result cannot be taken as a verdict come before
#: verdicts: the tool failed or the link broke (3), the run was cut short or left verdicts
#: open (2), the DUT could not be run as the rack asked (4: its port, its options). Then a
#: device shown non-compliant (1) before a port where nothing answered (5: no device, so no
#: evidence about one), and compliant (0) last.
WORST_FIRST = (
    EXIT_INTERNAL, EXIT_INCOMPLETE, EXIT_USAGE, EXIT_NON_COMPLIANT, EXIT_NO_DEVICE, EXIT_COMPLIANT
)  # fmt: skip
_MEANING = {
    EXIT_COMPLIANT: "compliant",
    EXIT_NON_COMPLIANT: "non-compliant",
    EXIT_INCOMPLETE: "incomplete",
    EXIT_INTERNAL: "internal error",
    EXIT_USAGE: "usage error",
    EXIT_NO_DEVICE: "no device",
}


def worst(codes: Sequence[int]) -> int:
    """The rack's exit status: the worst of its DUTs' (an unknown status counts as 3)."""
    rank = {code: i for i, code in enumerate(WORST_FIRST)}
    return min(codes, key=lambda c: rank.get(c, 0)) if codes else EXIT_USAGE


def meaning(code: int) -> str:
    return _MEANING.get(code, f"exit {code}")


def verdict_text(row: dict[str, Any]) -> str:
    """A DUT's verdict as the console and index.html show it: an incomplete run's verdict
    says so (an INCOMPLETE one already does)."""
    verdict = row["verdict"]
    if verdict is None:
        return "no verdict"
    return verdict if row["complete"] or verdict == "INCOMPLETE" else f"{verdict} (incomplete)"


def dut_row(dut: Any, role: str, result: dict[str, Any], folder: Path | None,
            rack_dir: Path) -> dict[str, Any]:  # fmt: skip
    """One DUT's row of rack.json from its worker's result; ``folder``: where its reports
    are now (None: it wrote none)."""
    document = result.get("document") or {}
    summary = document.get("summary") or {}
    ident = document.get("dut") or {}
    run = document.get("run") or {}
    return {
        "name": dut.name,
        "port": dut.port,
        "role": role,
        "worker": dut.tx,
        "host": result.get("host"),
        "folder": folder.relative_to(rack_dir).as_posix() if folder is not None else None,
        "exit_code": result["exit_code"],
        "meaning": meaning(result["exit_code"]),
        # a DUT with no verdicts.json ran nothing to completion
        "complete": bool(run.get("complete")) if document else False,
        "stop_reason": run.get("stop_reason"),
        "verdict": summary.get("verdict"),
        "counts": summary.get("counts"),
        "failed": document.get("failed") or [],
        "identification": (ident.get("identification") or "").strip() or None,
        "vendor": (ident.get("vendor") or "").strip() or None,
        "model": ident.get("model"),
        "serial": ident.get("serial"),
        "sdi12_version": ident.get("sdi12_version"),
        "wall_s": result.get("wall_s"),
        "errors": result.get("errors") or [],
    }


def rack_document(rows: list[dict[str, Any]], facts: dict[str, Any]) -> dict[str, Any]:
    """rack.json: the rack (``facts``: folder, times, workers, interrupted) and its DUTs."""
    code = worst([r["exit_code"] for r in rows])
    if facts.get("interrupted"):
        code = worst([code, EXIT_INCOMPLETE])
    rack = dict(facts)
    rack.update({
        "complete": all(r["complete"] for r in rows) and not facts.get("interrupted"),
        "exit_code": code,
        "meaning": meaning(code),
        "worst_first": list(WORST_FIRST),
    })  # fmt: skip
    return {"schema": SCHEMA, "rack": rack, "duts": rows}


def write_json(document: dict[str, Any], path: Path) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    return path
