"""``verdicts.json`` (contract ``sdi12-conform/verdicts/1``) and ``transcript.jsonl``.

Keep the shape stable: CI jobs and other tools script against it. Add keys, never rename.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

from ..dut import DutClaim
from ..links.bus_time import bus_time_again
from ..protocol.version import format_version
from ..replay.recording import write_recording
from ..results import counts
from ..run import TOOL_IDENTITY, ConformanceRun
from ..transcript import TOOL, EventKind, escape, write_jsonl
from ..view.segments import memo
from .evidence import Locator, WireRef, locator_of, wire_refs
from .margins import distribution_json, margins_json
from .plan import PLAN_FILE, read_plan
from .sweep_chart import sweeps_block

SCHEMA = "sdi12-conform/verdicts/1"


def identity_fields(address: str | None, claim: DutClaim) -> dict[str, Any]:
    """What a DUT said about itself, as ``dut`` and each entry of ``duts`` give it."""
    ident, version = claim.identity, claim.version
    return {
        "address": address,
        "identification": claim.reply,
        "sdi12_version": format_version(version) if version else None,
        "vendor": ident.vendor if ident else None,
        "model": ident.model if ident else None,
        "firmware": ident.sensor_version if ident else None,
        "serial": ident.optional if ident else None,
    }


def duts_block(run: ConformanceRun) -> list[dict[str, Any]] | None:
    """Every sensor the run saw on the bus (``duts``), in address order; None (the key left
    out) for a live run, which drives one DUT, the ``dut`` block's (Session.bus_sensors)."""
    found = run.session.bus_sensors() if run.session else None
    if found is None:
        return None
    return [identity_fields(address, claim) for address, claim in found]


def dut_block(run: ConformanceRun) -> dict[str, Any]:
    session = run.session
    claim = session.claim() if session else DutClaim()
    return {
        **identity_fields(session.address if session else run.options.address, claim),
        "assumptions": list(session.assumptions) if session else [],
        "declaration": run.declaration.source if run.declaration else None,
        # whether every address change was undone (design.md 7: leave the DUT as found)
        "address_notes": list(session.address_notes) if session else [],
    }


def bus_block(run: ConformanceRun) -> dict[str, Any]:
    """Bus-time lower bound next to the time the run took on the link's clock (wall time on
    a real link; virtual time on the sim bus, where ``wall_s`` is null)."""
    link = run.link
    if link is None:
        return {"bus_lower_bound_s": None, "wall_s": None, "efficiency": None}
    # kept on the transcript: each run of a passive judgement reads the one recording, its
    # events read again as they come (no list of them: issue 22)
    figures: dict[str, Any] = memo(
        link.transcript, "_bus_time", len(link.transcript),
        lambda: bus_time_again(link.events_again),
    ).to_json()  # fmt: skip
    elapsed = link.now()
    figures["link_clock_s"] = round(elapsed, 3)
    figures["wall_s"] = None if link.info.virtual_time else round(elapsed, 3)
    lower = figures["bus_lower_bound_s"]
    figures["efficiency"] = round(lower / elapsed, 3) if elapsed > 0 else None
    return figures


def plan_block(directory: Path) -> dict[str, Any] | None:
    plan = read_plan(directory)
    if plan is None:
        return None
    return {
        "file": PLAN_FILE,
        "expected_bus_s": plan.get("expected_bus_s"),
        "cases": len(plan.get("cases", [])),
    }


def build(run: ConformanceRun) -> dict[str, Any]:
    results = run.results or []
    # the run's events read through its locator: a recording's as they come again (issue 22)
    locator = locator_of(run.link) if run.link is not None else None
    refs = wire_refs(run.cases, run.link) if run.link is not None else {}
    return {
        "schema": SCHEMA,
        "tool": dict(TOOL_IDENTITY),
        "run": {
            "started": run.started,
            "finished": run.finished,
            "role": run.options.role,
            "port": run.options.port,
            "link": run.link_description(),
            "strict": run.options.strict,
            "complete": run.complete,
            "stop_reason": run.stop_reason or None,
            "partial": run.selection.partial,
            "selection": run.selection.describe() if run.selection.partial else None,
            "bus": bus_block(run),
        },
        "dut": dut_block(run),
        # a passive run: every sensor on the bus (issue 23), ``dut`` being this run's own
        **({"duts": duts} if (duts := duts_block(run)) is not None else {}),
        # the test plan the run was given (plan.json beside it), in short: planned vs judged
        "plan": plan_block(run.report_dir()),
        "summary": {"verdict": run.verdict, "counts": counts(results)},
        # every timed rule's smallest margin to its limit (finding "distribution": all of it)
        "margins": margins_json(results),
        "requirements": [
            {
                "id": r.requirement.id,
                "clause": r.requirement.clause,
                "level": r.requirement.level,
                "statement": r.requirement.statement,
                "testable": r.requirement.testable(run.options.role),
                "verdict": str(r.verdict),
                "selected": r.selected,
                "tests": r.tests,
                "findings": [_finding(f, refs.get(id(f))) for f in r.findings],
                "consequence_of": r.consequence_of,
            }
            for r in results
        ],
        "tests": [
            {
                "id": c.nodeid,
                "verdict": str(c.verdict),
                "requirements": list(c.requirements),
                "duration_s": round(c.duration, 4),
                # each declared precondition the case checked: "met" or why not
                "preconditions": dict(c.preconditions),
                "description": c.description,
                # what the case itself put on the bus: the run beside its plan (issue 24)
                "bus_s": None if c.bus_s is None else round(c.bus_s, 3),
                "sent": sent_by(locator, c.added) if locator is not None else [],
            }
            for c in run.cases
        ],
        **sweeps_block(run),  # --sweep only: the tolerance sweeps (informational)
    }


def sent_by(locator: Locator, added: tuple[int, int] | None) -> list[dict[str, Any]]:
    """The commands the tool sent in the run's events ``added`` (``locator`` reads them), in
    first-sent order, each with how often; ``breaks`` counts the breaks in front of them."""
    if added is None:
        return []
    counts: dict[str, dict[str, Any]] = {}
    text, broke = "", False
    for e in locator.slice(*added):
        if e.origin != TOOL:
            continue
        if e.kind is EventKind.BREAK:
            broke = True
        elif e.kind is EventKind.CHAR:
            text += chr(e.char7)
            if e.char7 == 0x21:  # '!' ends a command
                row = counts.setdefault(escape(text), {"command": escape(text), "times": 0,
                                                         "breaks": 0})  # fmt: skip
                row["times"] += 1
                row["breaks"] += broke
                text, broke = "", False
    return list(counts.values())


def _finding(f: Any, wire: WireRef | None = None) -> dict[str, Any]:
    return {
        "test": f.test,
        "verdict": str(f.verdict),
        "detail": f.detail,
        "measured_ms": f.measured_ms,
        "limit_ms": f.limit_ms,
        "uncertainty_ms": f.uncertainty_ms,
        "evidence": f.evidence,
        "decision": f.decision,
        "observed": f.observed,
        "consequence_of": f.consequence_of,
        # FAIL/WARN/INCONCLUSIVE: the exchange it rests on, as transcript.jsonl positions
        "wire": wire.to_json() if wire is not None else None,
        # timed rules: every measurement behind the verdict (margins, issue 24)
        "distribution": distribution_json(f),
    }


def write_transcript(run: ConformanceRun, directory: Path) -> Path:
    """``transcript.jsonl``: every event of the run's link (empty when no link opened). It is
    the evidence, written before verdicts.json so the manifest can pin it."""
    path = directory / "transcript.jsonl"
    if run.link is not None:
        transcript = run.link.transcript
        written = transcript.__dict__.get("_written_to")
        if written is not None and written[0] == len(transcript) and written[1].is_file():
            # the same events already written whole (each sensor's run of a passive
            # judgement writes the one recording: 43 MB an hour of a busy bus, 3 s to format)
            shutil.copyfile(written[1], path)
        else:
            if run.link.keeps_written_reading:
                write_recording(path, transcript.events)
            else:  # written as the events come again: no list of them (issue 22)
                write_jsonl(str(path), run.link.events_again())
            transcript.__dict__["_written_to"] = (len(transcript), path)
    else:
        path.write_text("", encoding="utf-8")
    return path


def write(run: ConformanceRun, directory: Path) -> Path:
    """``verdicts.json``, with the manifest of the files written before it
    (``sdi12-conform verify``); the document stays on the run for the caller."""
    from .manifest import build_manifest

    path = directory / "verdicts.json"
    run.document = build(run)  # what the command line prints and exits on: this run's own
    run.document["manifest"] = build_manifest(
        directory, run.options.declaration, str(TOOL_IDENTITY["version"])
    )
    path.write_text(json.dumps(run.document, indent=2, ensure_ascii=False), encoding="utf-8")
    return path
