"""One rack run: the workers started, each DUT's folder put in place as its result comes
(a worker elsewhere sends its files; ``--profile production`` names a folder by the
sensor's serial), a line per DUT as it finishes, then the rack's summary files and table."""

from __future__ import annotations

import datetime as dt
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..exits import EXIT_COMPLIANT, EXIT_INCOMPLETE, EXIT_NON_COMPLIANT, say_error
from ..interrupts import GUARD
from ..profiles import PROFILES
from ..report_folder import serial_folder_name
from .spec import RESERVED
from .summary import dut_row, rack_document, verdict_text, write_json

if TYPE_CHECKING:
    from rich.console import Console

    from ..run import RunOptions
    from .spec import Dut


def place_folder(rack_dir: Path, dut: Dut, result: dict[str, Any]) -> Path | None:
    """Put a DUT's reports in its folder of the rack (a worker elsewhere sent their files);
    the folder (None: the run wrote none)."""
    target = rack_dir / dut.name
    files = result.get("files")
    if files is not None:  # a worker on another host: its folder's files came back
        for name, data in files.items():
            path = target / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        return target
    folder = Path(result["folder"]) if result.get("folder") else None
    return folder if folder is not None and folder.is_dir() else None


def name_by_serial(rack_dir: Path, rows: list[dict[str, Any]]) -> None:
    """Rename each DUT's folder after its sensor's serial number (from ``aI!``), once every
    DUT has finished and in rack order, so the same rack names the same folders however
    its workers raced: ``SERIAL``, or ``SERIAL-NAME`` for a later unit of a serial already
    taken (a factory's duplicate serial, shown rather than hidden). ``rows`` (rack.json's)
    get their new folders; a folder that cannot be renamed keeps its name."""
    for row in rows:
        serial = serial_folder_name(row["serial"])
        if serial is None or row["folder"] is None:
            continue
        for name in (serial, f"{serial}-{row['name']}"):
            target = rack_dir / name
            if name in RESERVED or target.exists():
                continue
            try:
                (rack_dir / row["folder"]).rename(target)
            except OSError:
                break
            row["folder"] = name
            break


def job_for(options: RunOptions, dut: Dut, rack_dir: Path, plan: str) -> dict[str, Any]:
    """What a worker is sent: a worker on this host writes into the rack's folder, one
    elsewhere into a folder of its own whose files come back (and gets the declaration's
    text, the rack's files being out of its reach)."""
    import execnet

    local = bool(execnet.XSpec(dut.tx).popen)
    fields = vars(options) | {"report_dir": None}
    declaration = None
    if options.declaration and not local:
        declaration = Path(options.declaration).read_text(encoding="utf-8")
    return {
        "options": fields,
        "plan": plan,
        "report_dir": str(rack_dir / dut.name) if local else None,
        "declaration_text": declaration,
        "name": dut.name,
    }


def _line(prefix: str, row: dict[str, Any]) -> str:
    """One DUT's line: its verdict, exit status, time and folder, and why, where it has no
    verdict of its own."""
    text = (f"{prefix}{row['name']} ({row['port']}): {verdict_text(row)}, exit "
            f"{row['exit_code']} ({row['meaning']})")  # fmt: skip
    if row["wall_s"] is not None:
        text += f" in {row['wall_s']:.1f} s"
    if row["folder"]:
        text += f" -> {row['folder']}/"
    if row["exit_code"] not in (EXIT_COMPLIANT, EXIT_NON_COMPLIANT) and row["errors"]:
        text += f"; {row['errors'][-1]}"
    return text


def _table(console: Console, document: dict[str, Any], rack_dir: Path) -> None:
    """The rack in DUT order: a table on a terminal, a line per DUT in a log or a pipe
    (rich would fold a table's cells at 80 columns there)."""
    from rich.table import Table

    rack, rows = document["rack"], document["duts"]
    if console.is_terminal:
        table = Table(title=f"rack: {len(rows)} DUTs")
        for column in ("DUT", "port", "serial", "verdict", "exit", "folder"):
            table.add_column(column, overflow="fold")
        for row in rows:
            table.add_row(row["name"], row["port"], row["serial"] or "-", verdict_text(row),
                          f"{row['exit_code']} {row['meaning']}", row["folder"] or "-")  # fmt: skip
        console.print(table)
    else:
        console.print("rack summary:", markup=False, highlight=False)
        for row in rows:
            console.print(_line("  ", row), markup=False, highlight=False)
    console.print(
        f"rack: exit {rack['exit_code']} ({rack['meaning']}, the worst DUT's), "
        f"{rack['wall_s']:.1f} s wall; {rack_dir / 'index.html'} "
        f"(rack.json, junit.xml beside it)",
        markup=False,
        highlight=False,
    )


def _by_serial(options: RunOptions) -> bool:
    """Whether the DUT's profile names its folder by the sensor's serial (production)."""
    return options.profile is not None and PROFILES[options.profile].folder_by_serial


def run_rack(duts: list[Dut], per_dut: list[RunOptions], rack_dir: Path, plan: str,
             console: Console) -> int:  # fmt: skip
    """Run every DUT at once, one worker each; write the summary; the rack's exit status."""
    from .index_html import write_index
    from .junit import write_junit
    from .pool import Pool

    started, began = dt.datetime.now(dt.UTC).isoformat(timespec="seconds"), time.monotonic()
    workers = ", ".join(sorted({d.tx for d in duts}))
    console.print(f"rack: {len(duts)} DUTs, one worker each ({workers}) -> {rack_dir}",
                  markup=False, highlight=False)  # fmt: skip
    jobs = [job_for(o, d, rack_dir, plan) for o, d in zip(per_dut, duts, strict=True)]
    if GUARD.requested:  # Ctrl-C while the rack was being checked: no DUT was touched
        say_error("interrupted before the rack started: nothing was sent to any DUT; no report")
        return EXIT_INCOMPLETE
    rows: dict[int, dict[str, Any]] = {}

    def on_result(i: int, result: dict[str, Any]) -> None:
        folder = place_folder(rack_dir, duts[i], result)
        rows[i] = dut_row(duts[i], per_dut[i].role, result, folder, rack_dir)
        console.print(_line(f"[{len(rows)}/{len(duts)}] ", rows[i]), markup=False,
                      highlight=False)  # fmt: skip

    pool = Pool([d.tx for d in duts], jobs)
    try:
        pool.wait(on_result)
    finally:
        pool.close()
    interrupted = GUARD.close()
    ordered = [rows[i] for i in range(len(duts))]
    name_by_serial(rack_dir, [r for r, o in zip(ordered, per_dut, strict=True) if _by_serial(o)])
    facts = {
        "folder": str(rack_dir),
        "started": started,
        "finished": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
        "wall_s": round(time.monotonic() - began, 3),
        "workers": [d.tx for d in duts],
        "interrupted": interrupted,
    }
    document = rack_document(ordered, facts)
    write_json(document, rack_dir / "rack.json")
    write_junit(document["duts"], rack_dir)
    write_index(document, rack_dir)
    _table(console, document, rack_dir)
    return int(document["rack"]["exit_code"])
