"""The rack on the command line: ``sdi12-conform --port A --port B [options]``,
``sdi12-conform --rack FILE [options]`` and its alias ``sdi12-conform rack FILE [options]``.

Every option of the main command applies to every DUT (a rack file's ``role``, ``address`` and
``declaration`` override it for one DUT). The rack's folder (``--report-dir``, default
``reports/STAMP-rack``) holds one folder per DUT, named after the DUT (``--profile
production``: after the sensor's serial number from ``aI!``), and the rack's summary. The
exit status is the worst DUT's (:data:`conformance.rack.summary.WORST_FIRST`); a Ctrl-C stops
every worker and makes it 2.

Only the standard library at the top: the main command imports this module for every run.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console

    from ..run import RunOptions
    from .spec import Dut


def rack_ports(argv: list[str]) -> list[str]:
    """Every ``--port`` of the command line (the main parser keeps the last only)."""
    p = argparse.ArgumentParser(add_help=False)
    p.add_argument("--port", action="append", default=[])
    known, _ = p.parse_known_args(argv)
    return known.port


def is_rack(argv: list[str], args: argparse.Namespace) -> bool:
    """A rack run: ``--port`` twice or more, ``--rack FILE`` or a worker spec ``--tx``."""
    return bool(args.rack or args.tx or len(rack_ports(argv)) > 1)


def rack_argv(argv: list[str], console: Console) -> list[str] | int:
    """``sdi12-conform rack FILE [options]`` as the main command's ``--rack FILE [options]``;
    an exit status instead where there is nothing to run (``--help``, no file named)."""
    from ..exits import EXIT_COMPLIANT, EXIT_USAGE, say_error

    if argv and argv[0] in ("-h", "--help"):
        from . import spec

        console.print(
            "usage: sdi12-conform rack FILE [options of the main command]   (the same as "
            "sdi12-conform --rack FILE ...)\n" + (spec.__doc__ or ""),
            markup=False,
            highlight=False,
        )
        return EXIT_COMPLIANT
    if not argv or argv[0].startswith("-"):
        say_error("error: sdi12-conform rack FILE: name the rack file first (rack --help)")
        return EXIT_USAGE
    return ["--rack", *argv]


def _duts(argv: list[str], args: argparse.Namespace) -> list[Dut]:
    from ..options import UsageError
    from .spec import duts_from_ports, load_rack_file

    ports = rack_ports(argv)
    if args.rack and ports:
        raise UsageError("--rack names the ports; give no --port with it")
    if args.baseline:
        raise UsageError("--baseline compares one run; compare a rack's DUTs one by one "
                         "(sdi12-conform diff DUT_FOLDER BASELINE)")  # fmt: skip
    return load_rack_file(args.rack, args.tx) if args.rack else duts_from_ports(ports, args.tx)


def dut_options(template: RunOptions, dut: Dut) -> RunOptions:
    """The run options of one DUT: the command line's, with what the rack says of it."""
    return replace(
        template,
        port=dut.port,
        role=dut.role or template.role,
        address=dut.address if dut.address is not None else template.address,
        declaration=dut.declaration or template.declaration,
        report_dir=None,
    )


def _prepare(
    argv: list[str], args: argparse.Namespace, template: RunOptions
) -> tuple[list[Dut], list[RunOptions]]:
    """The rack's DUTs and their options, every portless check made (a usage error here
    stops the rack before any worker starts)."""
    from ..options import UsageError
    from ..preflight import check_options_offline

    duts = _duts(argv, args)
    per_dut = [dut_options(template, dut) for dut in duts]
    for dut, options in zip(duts, per_dut, strict=True):
        try:
            check_options_offline(options)
        except ValueError as exc:  # UsageError, DeclarationError, SelectionError
            raise UsageError(f"DUT {dut.name}: {exc}") from None
    return duts, per_dut


def rack_main(
    argv: list[str], args: argparse.Namespace, template: RunOptions, console: Console
) -> int:
    """Run the rack the command line names (``template``: its options, which every DUT
    starts from); its exit status, the worst DUT's."""
    from .. import report_folder
    from ..exits import EXIT_USAGE, say_error
    from ..preflight import check_report_dir

    try:
        duts, per_dut = _prepare(argv, args, template)
        rack_dir = report_folder.run_folder(args.report_dir, "rack")
        check_report_dir(rack_dir)
        report_folder.acquire(rack_dir)
    except (ValueError, OSError) as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    try:
        from .run import run_rack

        return run_rack(duts, per_dut, rack_dir, args.plan, console)
    finally:
        report_folder.release(rack_dir)
