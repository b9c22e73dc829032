"""Passive judging: every rule that traffic alone can show, on a recording no tool drove.

``judge_passively`` checks the recording can be read (a clear one-line error and exit 4 if
not, or if it holds no SDI-12 traffic), then runs the passive cases (``testcases.passive``)
once per role over the port ``recording:PATH?...``: the sensor rules aggregate as role
``sensor``, the recorder rules as role ``recorder``. ``--role both`` writes two report sets,
``<report-dir>/sensor/`` and ``<report-dir>/recorder/``, prints both verdicts and exits with
the worse of the two codes.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..conduct import RunResult, conduct
from ..exits import EXIT_COMPLIANT, EXIT_USAGE
from ..interrupts import GUARD
from ..links.errors import PortError
from ..offline.job import PassiveJob
from ..protocol.commands import Kind
from ..replay.recording_link import recording_port
from ..report_folder import run_folder
from ..run import RunOptions
from ..transcript import EventKind

if TYPE_CHECKING:
    from rich.console import Console

ROLES = ("sensor", "recorder")


def no_traffic(port: str) -> str | None:
    """Why the recording holds nothing to judge (None: it holds SDI-12 traffic)."""
    from ..offline.fixtures import recording_of
    from ..view.segments import read_view

    link = recording_of(port)
    events = [e for e in link.transcript.events if e.kind is not EventKind.NOTE]
    chars = [e for e in events if e.kind is EventKind.CHAR]
    breaks = [e for e in events if e.kind is EventKind.BREAK]
    view = read_view(events)
    commands = [t.command for t in view.transmissions if t.command is not None]
    # any text ending in '!' parses as an extended command: alone it is no sign of SDI-12
    if any(c.kind is not Kind.EXTENDED for c in commands) or (commands and breaks):
        return None
    bad = sum(1 for e in chars if not e.parity_ok)
    said = f"no SDI-12 traffic in {link.spec.path}: {len(chars)} character(s), "
    said += f"{len(breaks)} break(s) and no SDI-12 command (an address, a command, '!')"
    if not breaks:
        said += "; SDI-12 starts every exchange with a break"
    if bad:
        said += f"; {bad} character(s) fail 7E1 parity (another framing or bit rate?)"
    return said


def error(text: str) -> None:
    """One line on stderr, as the CLI's errors are (never on stdout, where results go)."""
    from rich.console import Console

    Console(stderr=True, soft_wrap=True).print(text, style="red", markup=False, highlight=False)


def forget(port: str) -> None:
    """Drop the loaded recording once judged (an in-process caller may judge many)."""
    from ..offline.fixtures import _LOADED

    _LOADED.pop(port, None)


def judge_passively(args: PassiveJob, console: Console) -> int:
    """Judge the recording ``args`` names; the exit code is the worse role's."""
    from ..declaration import DeclarationError, normalise_version
    from ..exits import EXIT_INCOMPLETE, EXIT_INTERNAL, EXIT_NON_COMPLIANT
    from ..reports.console import print_summary

    port = recording_port(
        args.recording, args.format, channel=args.channel, tx_channel=args.tx_channel,
        invert=args.invert, baud=args.baud,
    )  # fmt: skip
    try:
        if args.sdi_version:
            normalise_version(args.sdi_version)
        why = no_traffic(port)
    except (PortError, DeclarationError) as exc:
        forget(port)
        error(f"error: {exc}")
        return EXIT_USAGE
    if why is not None:
        forget(port)
        error(f"error: {why}")
        return EXIT_USAGE
    roles = ROLES if args.role == "both" else (args.role,)
    base = run_folder(args.report_dir, "passive")
    console.print(
        f"judging {args.recording} passively: the rules its traffic can show "
        f"({' and '.join(roles)} rules)",
        markup=False,
        highlight=False,
    )
    codes = []
    for role in roles:
        report_dir = base / role if len(roles) > 1 else base
        result = _run_role(role, port, report_dir, args, console)
        code, data = result.pytest_code, result.document
        codes.append(code)
        if GUARD.requested and data is None:  # Ctrl-C before this role wrote its verdicts
            forget(port)
            return EXIT_INCOMPLETE
        if data is None:  # the role's run wrote no verdicts (its own, never a file's)
            if code in (EXIT_USAGE, EXIT_INTERNAL):
                return code
            error(f"error: the {role} rules were not judged (pytest exit {code})")
            return EXIT_INTERNAL
        console.print(f"{role} rules:", style="bold", markup=False, highlight=False)
        print_summary(console, data, str(report_dir))
        codes[-1] = result.exit_code
        if GUARD.requested:  # Ctrl-C: this role's report says so; the next one is not begun
            forget(port)
            GUARD.close()
            return EXIT_INCOMPLETE
    forget(port)
    order = (EXIT_INTERNAL, EXIT_USAGE, EXIT_NON_COMPLIANT, EXIT_INCOMPLETE, EXIT_COMPLIANT)
    return min(codes, key=lambda c: order.index(c) if c in order else -1)


def _run_role(
    role: str, port: str, report_dir: Path, args: PassiveJob, console: Console
) -> RunResult:
    """One role's rules: the passive cases over the recording's port, aggregated as ``role``."""
    from ..reports.console import ProgressPlugin

    options = RunOptions(
        port=port,
        role=role,
        report_dir=str(report_dir),
        address=args.address if role == "sensor" else None,
        version=args.sdi_version,
        strict=args.strict,
    )
    return conduct(options, cases="testcases.passive", plugins=[ProgressPlugin(console)])


__all__ = ["EXIT_COMPLIANT", "judge_passively"]
