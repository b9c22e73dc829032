"""``sdi12-conform verify DIR``: does a run folder hold what its verdicts say?

A certifier receiving a folder has no device. Two checks stand in for it:

1. the manifest's hashes (:mod:`conformance.reports.manifest`): the recording is the one the
   verdicts were judged from;
2. the recording judged again by replay, offline, and every requirement's verdict compared
   with the one in ``verdicts.json`` (an edited verdict shows here, since no hash inside a
   file can pin that file), and the summary recounted from the requirements.

Exit 0 when both hold, 1 when anything does not (each line names the file and what differs),
2 when the folder cannot be re-judged by replay (the hashes are still checked and shown),
4 when it is not a run folder.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from ..exits import EXIT_INCOMPLETE, EXIT_NON_COMPLIANT, EXIT_OK, EXIT_USAGE, say_error
from ..reports.diff import DiffError, load_run
from ..reports.manifest import check_files

if TYPE_CHECKING:
    from rich.console import Console


#: the ``judge`` subcommand (the CLI hands it in, as it does to ``monitor``)
Judge = Callable[[list[str], "Console"], int]


def verify_main(argv: list[str], console: Console, judge: Judge) -> int:
    p = argparse.ArgumentParser(
        prog="sdi12-conform verify",
        description="Check a run folder without the device: the manifest's hashes, then the "
        "recording judged again by replay and compared with verdicts.json.",
    )
    p.add_argument("folder", metavar="DIR", help="a run folder (verdicts.json, transcript.jsonl)")
    args = p.parse_args(argv)
    folder = Path(args.folder)
    try:
        if not folder.exists():  # a mistyped path: "not a run folder" read as a bad folder
            raise DiffError(f"{folder}: no such folder")
        if not folder.is_dir():
            raise DiffError(f"{folder}: not a run folder")
        data = load_run(folder)
    except DiffError as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE

    def say(ok: bool | None, text: str) -> None:
        mark = {True: "ok   ", False: "FAIL ", None: "note "}[ok]
        console.print(f"{mark} {text}", markup=False, highlight=False)

    problems = 0
    manifest = data.get("manifest")
    if not manifest:
        say(False, "verdicts.json has no manifest (made by a version without one)")
        problems += 1
    else:
        for name, ok, why in check_files(folder, manifest):
            say(ok, f"{name}: {why}")
            problems += not ok
    # a partial run (-k, --req) counts only what it selected (results.counts)
    recount = Counter(r["verdict"] for r in data.get("requirements", []) if r.get("selected", True))
    counts = (data.get("summary") or {}).get("counts") or {}
    if any(counts.get(v, 0) != recount.get(v, 0) for v in set(counts) | set(recount)):
        say(False, f"verdicts.json: summary counts {counts} do not match its requirements")
        problems += 1
    rejudged = _rejudge(folder, console, judge)
    if rejudged is None:
        say(None, "not re-judged: the recording cannot be replayed (see the note above)")
        return EXIT_NON_COMPLIANT if problems else EXIT_INCOMPLETE
    recorded = {r["id"]: r["verdict"] for r in data.get("requirements", [])}
    again = {r["id"]: r["verdict"] for r in rejudged.get("requirements", [])}
    differ = sorted(k for k in recorded.keys() | again.keys() if recorded.get(k) != again.get(k))
    for rid in differ:
        say(
            False,
            f"verdicts.json: {rid} says {recorded.get(rid)}, the recording gives {again.get(rid)}",
        )
    problems += len(differ)
    if not differ:
        say(True, f"re-judged by replay: all {len(recorded)} verdicts follow from the recording")
    verdict, again_verdict = data["summary"].get("verdict"), rejudged["summary"]["verdict"]
    if verdict != again_verdict:
        say(False, f"verdicts.json: overall {verdict}, the recording gives {again_verdict}")
        problems += 1
    console.print(
        f"{folder}: " + ("verified" if not problems else f"{problems} problem(s)"),
        markup=False,
        highlight=False,
    )
    return EXIT_NON_COMPLIANT if problems else EXIT_OK


def _rejudge(folder: Path, console: Console, judge: Judge) -> dict | None:
    """The folder judged again by replay into a scratch folder; None if it cannot be (its
    verdicts came out of passive judging, or none at all: ``judge``'s notes say why)."""
    from io import StringIO

    from rich.console import Console as RichConsole

    from ..replay.link import SCHEME

    said = StringIO()
    with tempfile.TemporaryDirectory(prefix="sdi12-verify-") as tmp:
        out = Path(tmp) / "rejudged"
        judge([str(folder), "--report-dir", str(out)], RichConsole(file=said, width=200))
        file = out / "verdicts.json"
        data = json.loads(file.read_text(encoding="utf-8")) if file.is_file() else None
    if data is not None and str(data["run"]["port"]).startswith(SCHEME):
        return data
    for line in said.getvalue().splitlines():
        if line.startswith(("note:", "error:")):
            console.print(line, markup=False, highlight=False)
    return None
