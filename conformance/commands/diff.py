"""``sdi12-conform diff A B`` and a run's ``--baseline DIR``: the comparison of
:mod:`conformance.reports.diff` on the command line, with its exit codes (a contract):

- 0: nothing got worse (verdicts and findings; margins and identification are listed only);
- 1: at least one change for the worse;
- 4: a run that cannot be read or compared (usage).

With ``--baseline`` a run's exit code follows the comparison instead of COMPLIANT/NON-COMPLIANT
(0 or 1), so a device with known deviations is gated on gaining no new ones; an incomplete
run, an internal error or no device keep their own codes (2, 3, 5).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from ..exits import EXIT_NON_COMPLIANT, EXIT_OK, EXIT_USAGE, say_error
from ..reports.diff import DiffError, diff_json, diff_runs, diff_text, load_run, worse

if TYPE_CHECKING:
    from rich.console import Console


def diff_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform diff",
        description="What changed from run A to run B: verdicts, findings added or gone, "
        "timing figures that moved by more than their uncertainty, the identification. "
        "Exit 1 when anything got worse, 0 otherwise, 4 when a run cannot be read.",
    )
    p.add_argument("a", metavar="A", help="the earlier run: its folder or its verdicts.json")
    p.add_argument("b", metavar="B", help="the later run: its folder or its verdicts.json")
    p.add_argument("--json", action="store_true", help="print the comparison as JSON")
    return p


def diff_main(argv: list[str], console: Console) -> int:
    args = diff_parser().parse_args(argv)
    try:
        changes = diff_runs(load_run(args.a), load_run(args.b))
    except DiffError as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    if args.json:
        console.print_json(json.dumps(diff_json(changes, args.a, args.b)))
    else:
        for line in diff_text(changes, args.a, args.b):
            console.print(line, markup=False, highlight=False)
    return EXIT_NON_COMPLIANT if worse(changes) else EXIT_OK


def against_baseline(
    baseline: dict, name: str, data: dict, run_dir: Path, code: int, console: Console
) -> int:
    """Print the comparison at the end of a run, write it beside the run's reports
    (``baseline-diff.json``), and give the run's exit code under ``--baseline``."""
    try:
        changes = diff_runs(baseline, data)
    except DiffError as exc:
        say_error(f"error: --baseline {name}: {exc}")
        return EXIT_USAGE
    (run_dir / "baseline-diff.json").write_text(
        json.dumps(diff_json(changes, name, str(run_dir)), indent=1) + "\n", encoding="utf-8"
    )
    for line in diff_text(changes, name, str(run_dir)):
        console.print(line, markup=False, highlight=False)
    if code not in (EXIT_OK, EXIT_NON_COMPLIANT):
        return code
    return EXIT_NON_COMPLIANT if worse(changes) else EXIT_OK
