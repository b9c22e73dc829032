"""``sdi12-conform kit arduino SKETCH_DIR --lib PATH``: compile a sketch (and the user's copy
of its libraries) with the kit's Arduino core for the host, then run the suite on it through
``--port exec:`` (docs/kit.md). Every option the kit does not know goes to the run as it is
(``--role``, ``--declaration``, ``--report-dir``, ``-k`` ...), so the kit is the ordinary
command with the build in front of it and the exit codes are the run's (4 when the sketch
does not compile: a usage error, never a verdict)."""

from __future__ import annotations

import argparse
import shlex
from collections.abc import Callable
from pathlib import Path

from ..exits import EXIT_OK, EXIT_USAGE, say_error
from ..kit.build import ArduinoBuild, KitBuildError, build_arduino

#: the main command (the CLI hands it in): run the suite with these arguments
Run = Callable[[list[str]], int]


def kit_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform kit",
        allow_abbrev=False,  # the run's own options pass through untouched
        description="Compile firmware with the kit for the host and run the suite on it "
        "(any other option is the run's: --role, --declaration, --report-dir, -k ...).",
    )
    p.add_argument("flavour", choices=["arduino"], help="what the firmware is written for")
    p.add_argument("sketch", metavar="SKETCH_DIR", type=Path, help="the sketch folder (*.ino)")
    p.add_argument(
        "--lib",
        action="append",
        default=[],
        type=Path,
        metavar="PATH",
        help="a library folder the sketch uses (its src/ or its top folder; repeatable)",
    )
    p.add_argument(
        "-D",
        "--define",
        action="append",
        default=[],
        metavar="NAME[=VALUE]",
        help="a preprocessor definition (a faulty twin: -D FAULT_BAUD; repeatable)",
    )
    p.add_argument(
        "--pin",
        type=int,
        help="the SDI-12 data pin (default: the first pin given to attachInterrupt)",
    )
    p.add_argument(
        "--build-dir",
        type=Path,
        help="where the binary is built and cached (default .sdi12-kit/SKETCH)",
    )
    p.add_argument(
        "--build-only",
        action="store_true",
        help="compile, print the binary's path and the exec: port, and stop",
    )
    return p


def kit_main(argv: list[str], run: Run) -> int:
    args, rest = kit_parser().parse_known_args(argv)
    if any(a == "--port" or a.startswith("--port=") for a in rest):
        say_error("error: the kit sets --port itself (exec: on the compiled sketch)")
        return EXIT_USAGE
    build = ArduinoBuild(
        args.sketch,
        tuple(args.lib),
        tuple(args.define),
        data_pin=args.pin,
        build_dir=args.build_dir,
    )
    try:
        binary = build_arduino(build)
    except KitBuildError as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    port = f"exec:{shlex.quote(str(binary))}"
    if args.build_only:
        print(binary)
        print(port)
        return EXIT_OK
    return run([*rest, "--port", port])
