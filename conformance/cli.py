"""``sdi12-conform``: run the conformance suite against a device and gate CI on the verdict.

Exit codes (documented in the README): 0 compliant, 1 non-compliant, 2 interrupted or
incomplete, 3 internal error, 4 usage error, 5 no device answered.
"""

from __future__ import annotations

if __name__ == "__main__":  # `python -m conformance.cli`: Ctrl-C is ours before the imports
    from conformance.interrupts import GUARD as _EARLY_GUARD

    _EARLY_GUARD.install()

# In the tool's own process only (not wherever pytest loads the plugin), before the tool's,
# pytest's and hypothesis's dataclasses are defined: their generated methods' code is read
# from the installation's cache instead of being compiled again (conformance.dataclass_code)
from . import dataclass_code

if dataclass_code.CACHE is None:
    dataclass_code.install()

import argparse
import gc
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO, cast

from . import gc_pace
from .exits import (
    EXIT_COMPLIANT,
    EXIT_INCOMPLETE,
    EXIT_INTERNAL,
    EXIT_NON_COMPLIANT,
    EXIT_USAGE,
    PYTEST_NO_TESTS,
)
from .interrupts import GUARD

if TYPE_CHECKING:
    from rich.console import Console

    from .run import RunOptions

EXAMPLES = """\
examples:
  sdi12-conform --port sim --role sensor                  judge the built-in simulated sensor
  sdi12-conform --port 'sim://?faults=no-service-request' run against a faulty simulated sensor
  sdi12-conform --port sim --sdi-version 1.3 -k crc       a partial run: cases matching 'crc'
  sdi12-conform --port /dev/ttyUSB0 --req 4.4.12          a partial run: clause 4.4.12 only
  sdi12-conform --port sim --role recorder                 judge the golden recorder (sim)
  sdi12-conform --port 'sim://?recorder-faults=no-retries' --role recorder
                                                           a faulty golden recorder
  sdi12-conform list                                       the requirement catalog with coverage
  sdi12-conform faults                                     the emulator faults and what they break
  sdi12-conform matrix                                     run the fault-detection matrix
  sdi12-conform emulate --listen 127.0.0.1:4001            serve the emulator over RFC 2217
  sdi12-conform calibrate --port /dev/ttyUSB0              measure the bench's timing first
  sdi12-conform monitor --port /dev/ttyUSB0                listen to a live bus (never transmits)
  sdi12-conform --port sim --port 'sim://?faults=wrong-crc' a rack: one worker per port
  sdi12-conform rack bench.toml --profile production       a rack file's DUTs, in parallel

exit codes (every subcommand): 0 compliant/success, 1 non-compliant (matrix: a fault not
  caught exactly), 2 interrupted/incomplete, 3 internal error, 4 usage error, 5 no device
  answered. Ctrl-C: exit 2 and a report saying complete: false.
"""


def subcommands_text() -> str:
    """The subcommands, for the main help and for a mistyped one."""
    width = max(len(name) for name in SUBCOMMAND_HELP)
    rows = "".join(f"  {name:<{width}}  {what}\n" for name, what in SUBCOMMAND_HELP.items())
    return "subcommands (sdi12-conform SUBCOMMAND --help for each):\n" + rows


PLAN_CHOICES = ("auto", "always", "never")


def _plan_default() -> str:
    """``--plan``'s default: auto, or ``SDI12_PLAN`` (the tool's own tests set never: their
    real-time runs must not each pay, and load the machine with, a dry run)."""
    chosen = os.environ.get("SDI12_PLAN", "auto")
    return chosen if chosen in PLAN_CHOICES else "auto"


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform",
        usage="%(prog)s [options]  |  %(prog)s SUBCOMMAND ...",
        description="SDI-12 (v1.3/v1.4) conformance test suite: judges a sensor or a data "
        "recorder against every testable requirement and writes HTML, JSON and JUnit "
        "reports.\n\n" + subcommands_text(),
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    from . import __version__  # importlib.metadata: not before Ctrl-C is taken over
    from .options import add_cli_options

    p.add_argument("--version", action="version", version=f"sdi12-conform {__version__}")
    add_cli_options(
        p,
        (
            "port",
            "role",
            "address",
            "sdi-version",
            "declaration",
            "report-dir",
            "strict",
            "timing-uncertainty-ms",
            "echo",
            "direction",
            "trigger",
            "job-timeout",
            "sweep",
        ),
    )
    p.add_argument(
        "-k",
        dest="keyword",
        help="a partial run: only cases matching this pytest -k expression (exit 0/1 on "
        "what was selected; the rest is listed as not selected)",
    )
    add_cli_options(p, ("req", "profile"))
    p.add_argument(
        "--baseline",
        metavar="DIR",
        help="compare the run with an earlier one (its folder or verdicts.json) at its end; "
        "the exit code is then 1 if anything got worse, 0 if not (sdi12-conform diff --help)",
    )
    p.add_argument(
        "--plan",
        choices=PLAN_CHOICES,
        default=_plan_default(),
        help="write the test plan (sdi12-conform plan) into the run folder first and show it "
        "in the report beside what was judged; auto: on real-time links, where the run takes "
        "minutes and the dry run a few seconds (default: auto, or $SDI12_PLAN)",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="show pytest's own output")
    rack = p.add_argument_group(
        "a rack (many DUTs in one run, each in a worker process of its own: --port given "
        "more than once, or --rack FILE; README 'A rack')"
    )
    rack.add_argument(
        "--rack",
        metavar="FILE",
        help="a TOML rack file naming each DUT's port, and where they differ, its role, "
        "address, declaration, folder name and worker (sdi12-conform rack --help)",
    )
    rack.add_argument(
        "--tx",
        action="append",
        default=[],
        metavar="SPEC",
        help="where the workers run, as pytest-xdist's --tx: popen (default), "
        "ssh=HOST//python=PATH, N*SPEC; repeatable, given to the DUTs in turn",
    )
    return p


def options_from_args(args: argparse.Namespace) -> RunOptions:
    """The main command's parsed arguments as the run's options (every option spelled once,
    in :mod:`conformance.options`)."""
    from .options import cli_values
    from .run import RunOptions

    return RunOptions.from_values(cli_values(args), args.keyword)


def run_suite(
    options: RunOptions,
    console: Console,
    *,
    plan: str | None = None,
    baseline: str | None = None,
    verbose: bool = False,
) -> tuple[int, dict | None]:
    """The main command: check ``options``, run the suite, show the summary; the exit code
    and the run's verdicts.json document (None: none). ``plan``: write the test plan first
    (always/auto/never; default $SDI12_PLAN or auto); ``baseline``: an earlier run to compare
    with at the end."""
    from . import report_folder
    from .declaration import DeclarationError
    from .options import UsageError
    from .ports import PortError
    from .preflight import check_report_dir
    from .report_folder import run_folder
    from .selection import SelectionError

    refused: tuple[type[Exception], ...] = (
        DeclarationError, PortError, UsageError, SelectionError
    )  # fmt: skip
    if baseline:  # the comparison's module only for a run that compares
        from .reports.diff import DiffError, load_run

        refused += (DiffError,)

    if options.port is None:
        options.port = "sim"
        console.print(
            f"note: no --port given: judging the built-in SIMULATED {options.role}, not a real "
            "device (pass --port /dev/ttyUSB0, COM3 or rfc2217://HOST:PORT for one)",
            style="bold yellow",
            markup=False,
        )
    try:
        real_time = check_run_options(options)
        if _OWN_PROCESS and not real_time:  # a bounded run: no collections (gc_pace)
            gc_pace.never_in_this_process()
        # the baseline is read before the run: a bad path is a usage error, not a late one
        baseline_run = load_run(baseline) if baseline else None
        # a folder of this run's own: a new one, or the named one unless a live run holds it
        own_folder = not options.report_dir
        report_dir = run_folder(options.report_dir, options.role)
        options.report_dir = str(report_dir)
        check_report_dir(report_dir)
        report_folder.acquire(report_dir)
    except refused as exc:
        from .links.errors import PortMissing

        also = f", or judge the built-in simulated {options.role} with --port sim"
        error(f"error: {exc}{also if isinstance(exc, PortMissing) else ''}")
        return EXIT_USAGE, None
    try:
        plan = plan or _plan_default()
        if plan == "always" or (plan == "auto" and real_time):
            _plan_first(options, report_dir, console)
            if GUARD.requested:  # Ctrl-C during the dry run: nothing has gone on the bus
                error("interrupted while planning: nothing was sent to the device; no report")
                return EXIT_INCOMPLETE, None
            GUARD.reset()  # the dry run closed the guard: the run proper starts afresh
        return _conducted(options, console, baseline, baseline_run, verbose, own_folder)
    finally:
        report_folder.release(report_dir)


def check_run_options(options: RunOptions) -> bool:
    """Refuse what the run cannot use before anything goes on the bus (a usage error, exit 4,
    rather than a late one); whether the port runs in real time."""
    from .preflight import check_options_offline

    check_options_offline(options)
    if options.role == "recorder":
        from .recorder.scenario_runner import check_port

        return check_port(options.port, options.trigger)  # the port and recorder first
    from .ports import open_port

    # a port that cannot be opened (a sim URL's unknown fault too): a usage error
    link = open_port(options.port, echo=options.echo, direction=options.direction).link
    real_time = not link.info.virtual_time
    link.close()
    return real_time


def _plan_first(options: RunOptions, report_dir: Path, console: Console) -> None:
    """The test plan into the run folder before the run (issue 24): the report shows it next
    to what was judged, and the user sees how long the run will take on the bus. A Ctrl-C
    during the dry run stops it at its next case (the shared guard records it)."""
    from .commands.plan import cached_plan
    from .reports.plan import duration, write_plan

    plan = cached_plan(options.role, options.declaration, options.version, options.keyword,
                     tuple(options.requirements), options.profile)  # fmt: skip
    if GUARD.requested:
        return  # a plan cut short by Ctrl-C is no plan
    write_plan(report_dir, plan)
    console.print(
        f"plan: {len(plan['cases'])} cases, about {duration(plan['expected_bus_s'])} on the bus "
        f"(at least; {report_dir / 'plan.json'})",
        markup=False,
        highlight=False,
    )


def _folder_by_serial(profile: str | None) -> bool:
    """Whether the run's profile names its own folder by the sensor's serial number."""
    from .profiles import PROFILES

    return profile is not None and PROFILES[profile].folder_by_serial


def _conducted(
    options: RunOptions,
    console: Console,
    baseline: str | None,
    baseline_run: dict | None,
    verbose: bool,
    own_folder: bool = False,
) -> tuple[int, dict | None]:
    """The suite in this process; the summary and exit code from its own results.
    ``own_folder``: the run made its folder (no --report-dir), which a profile such as
    production then names by the sensor's serial number."""
    from .conduct import conduct
    from .selection import resolve

    plugins: list[object] = []
    if not verbose:
        from .reports.console import ProgressPlugin

        plugins.append(ProgressPlugin(console))
    # the main command's own process: report.html may be rendered beside the rest
    if _OWN_PROCESS:  # and jinja2 loaded only where it is (reports.page_template)
        from .reports.page_template import page_plugin_without_jinja2

        page_plugin_without_jinja2()
    result = conduct(options, verbose=verbose, plugins=plugins, html_aside=_OWN_PROCESS)
    report_dir, code, data = result.report_dir, result.pytest_code, result.document
    if data is not None and own_folder and _folder_by_serial(options.profile):
        from .report_folder import named_by_serial

        report_dir = named_by_serial(report_dir, data["dut"].get("serial"), options.role)
    interrupted = GUARD.close()  # the run is over: a later Ctrl-C leaves its report alone
    if interrupted and data is None:
        error("interrupted before the run started; no report written")
        return EXIT_INCOMPLETE, None
    if code == PYTEST_NO_TESTS and data is None:  # e.g. -k matched none
        for leftover in ("report.html", "junit.xml"):  # pytest-html's empty page misleads
            (report_dir / leftover).unlink(missing_ok=True)
        error(
            f"error: no conformance case matched -k {options.keyword!r}; "
            "`sdi12-conform list` shows the cases"
        )
        return EXIT_USAGE, None
    if data is None:
        error(f"error: the suite did not run (pytest exit {code}); rerun with -v")
        return (EXIT_INTERNAL if code == EXIT_INTERNAL else EXIT_USAGE), None
    from .reports.console import print_summary

    print_summary(console, data, str(report_dir))
    from .run_notes import req_pulled_in, version_mismatch

    wanted = list(options.requirements)
    for note in (
        req_pulled_in(data, resolve(options.role, wanted) if wanted else set(), wanted),
        version_mismatch(data, options.version),
    ):
        if note:
            console.print(f"note: {note}", style="yellow", markup=False, highlight=False)
    exit_status = result.exit_code
    assert exit_status is not None  # a document was written
    if interrupted:
        return EXIT_INCOMPLETE, data
    if baseline_run is not None:
        from .commands.diff import against_baseline

        return against_baseline(
            baseline_run, baseline, data, report_dir, exit_status, console
        ), data
    return exit_status, data


def cmd_judge(argv: list[str], console: Console) -> int:
    """``judge FILE``: replay a virtual-time run through the cases, or judge passively."""
    from .offline.judge import JudgeError, capture_replay_stopped, plan

    try:
        found = plan(argv)
    except JudgeError as exc:
        error(f"error: {exc}")
        return EXIT_USAGE
    if GUARD.requested:  # Ctrl-C while the recording was read and decoded
        error("interrupted before judging started; no report written")
        return EXIT_INCOMPLETE
    for note in found.notes:
        console.print(f"note: {note}", markup=False, highlight=False)
    if found.replay is not None:
        console.print(
            f"judging {found.path} by replay: the run's cases ask again, the recording answers",
            markup=False,
            highlight=False,
        )
        code, document = run_suite(found.replay, console)
        why = capture_replay_stopped(found, document) if code == EXIT_INTERNAL else None
        if why is not None:
            console.print(f"note: {why}", markup=False, highlight=False)
            return EXIT_INCOMPLETE
        return code
    from .commands.passive import judge_passively

    assert found.passive is not None  # plan() gives one or the other
    return judge_passively(found.passive, console)


def cmd_list(argv: list[str], console: Console) -> int:
    p = argparse.ArgumentParser(
        prog="sdi12-conform list", description="the requirement catalog with coverage"
    )
    p.add_argument(
        "--role",
        default="sensor",
        choices=("sensor", "recorder"),
        help="whose requirements: the sensor's (default) or the data recorder's",
    )
    args = p.parse_args(argv)
    from rich.table import Table

    from .coverage import coverage_rows

    table = Table(title=f"requirements, {args.role} role")
    for col in ("ID", "level", "testable", "cases / why not", "requirement"):
        table.add_column(col, overflow="fold")
    rows = coverage_rows(args.role)
    for row in rows:
        table.add_row(
            row.id,
            row.level,
            "yes" if row.testable else "no",
            "\n".join(row.cases) if row.testable else row.reason,
            row.statement,
        )
    console.print(table)
    covered = sum(1 for r in rows if r.testable and r.cases)
    testable = sum(1 for r in rows if r.testable)
    console.print(
        f"{covered}/{testable} testable requirements covered by a case; "
        f"{len(rows) - testable} untestable for this role",
        highlight=False,
    )
    return EXIT_COMPLIANT


def cmd_faults(argv: list[str], console: Console) -> int:
    p = argparse.ArgumentParser(
        prog="sdi12-conform faults",
        description="the emulator's faults and the requirements each breaks",
    )
    p.add_argument(
        "--role",
        default="sensor",
        choices=("sensor", "recorder"),
        help="the simulated sensor's faults and firmware profiles (default), or the golden "
        "recorder's faults (sim://?recorder-faults=NAME[,NAME] with --role recorder; faults "
        "that change one thing apart are refused)",
    )
    args = p.parse_args(argv)
    from rich.table import Table

    if args.role == "recorder":
        from .commands.fault_tables import recorder_faults_table

        console.print(recorder_faults_table())
        return EXIT_COMPLIANT

    from .emulator import FAULTS

    table = Table(title=f"{len(FAULTS)} emulator faults (use sim://?faults=NAME[,NAME])")
    width = max(len(name) for name in FAULTS)
    table.add_column("fault", no_wrap=True, min_width=width)  # a name to type: never cut
    table.add_column("violates", overflow="fold")
    table.add_column("what it does", overflow="fold")
    for name, fault in sorted(FAULTS.items()):
        table.add_row(name, " ".join(fault.violates), fault.description)
    console.print(table)
    from .emulator.profiles import PROFILES

    profiles = Table(title=f"{len(PROFILES)} firmware profiles (use sim://?profile=NAME)")
    profiles.add_column("profile", no_wrap=True, min_width=max(len(n) for n in PROFILES))
    profiles.add_column("faults", overflow="fold")
    profiles.add_column("what real firmware does", overflow="fold")
    for name, profile in PROFILES.items():
        quirks = [f"{k}={v}" for k, v in profile.quirks.items()]
        profiles.add_row(name, " ".join((*profile.faults, *quirks)), profile.description)
    console.print(profiles)
    return EXIT_COMPLIANT


def _matrix_parser() -> argparse.ArgumentParser:
    """``sdi12-conform matrix``'s options: single faults, or combinations of either role's."""
    p = argparse.ArgumentParser(
        prog="sdi12-conform matrix",
        description="run the sensor suite against every emulator fault and show which "
        "requirements each one made FAIL or WARN (exit 1 if any fault is not caught exactly)",
    )
    p.add_argument("--faults", help="comma-separated fault names (default: all)")
    p.add_argument("--jobs", type=int, default=2, help="parallel runs (default 2)")
    p.add_argument(
        "--through-capture",
        action="store_true",
        help="also export each fault's run as a sigrok capture and judge that: a row is exact "
        "only if the capture gives the run's verdicts (about twice the time)",
    )
    p.add_argument(
        "--combinations",
        type=int,
        metavar="N",
        help="instead of single faults, run N combinations of faults drawn by a seeded sampler "
        "(exit 1 if any has a FAIL/WARN outside its members' requirements or a missed FAIL)",
    )
    p.add_argument(
        "--all-pairs",
        action="store_true",
        help="with --role recorder: every pair of recorder faults that composes, in name order, "
        "instead of --combinations N drawn ones",
    )
    p.add_argument("--size", type=int, choices=(2, 3), default=2, help="faults per combination")
    p.add_argument("--seed", type=int, help="the sampler's seed (the same list for the same seed)")
    p.add_argument(
        "--role",
        choices=("sensor", "recorder"),
        default="sensor",
        help="with --combinations: combine the emulator's faults (sensor, default) or the "
        "golden recorder's (recorder: sim://?recorder-faults=A,B against the recorder suite)",
    )
    return p


def cmd_matrix(argv: list[str], console: Console) -> int:
    """Run the fault-detection matrix and print it: every emulator fault against the suite."""
    p = _matrix_parser()
    args = p.parse_args(argv)
    if args.combinations is not None or args.all_pairs:
        return _combination_matrix(args, console)
    if args.role == "recorder":
        error(
            "error: matrix --role recorder runs combinations (--combinations N); the single "
            "recorder faults' matrix is tests/matrices/test_recorder_matrix.py (pytest -m matrix)"
        )
        return EXIT_USAGE
    from rich.table import Table

    from .matrices.sensor_matrix import MatrixRow, fault_matrix

    names = [f for f in (args.faults or "").split(",") if f] or None
    from .emulator import FAULTS

    unknown = [n for n in names or () if n not in FAULTS]
    if unknown:
        from .suggest import did_you_mean

        error(
            f"error: unknown fault(s) {', '.join(unknown)}{did_you_mean(unknown, FAULTS)}; "
            "`sdi12-conform faults` lists the known ones"
        )
        return EXIT_USAGE
    if args.jobs < 1:
        error(f"error: --jobs must be 1 or more, not {args.jobs}")
        return EXIT_USAGE
    status = make_console(stderr=True)

    def progress(done: int, total: int, row: MatrixRow) -> None:
        caught = "caught exactly" if row.exact else "NOT caught exactly"
        status.print(f"[{done}/{total}] {row.fault}: {caught}", markup=False, highlight=False)

    status.print(f"running the sensor suite once per fault, {args.jobs} at a time...")
    if args.through_capture:
        from .matrices.roundtrip import row_through_capture

        rows = fault_matrix(names, args.jobs, progress, row=row_through_capture)
    else:
        rows = fault_matrix(names, processes=args.jobs, progress=progress)
    table = Table(title="fault-detection matrix (sensor role)")
    columns = ("fault", "declared", "FAIL/WARN", "caught")
    for col in columns + (("through a capture",) if args.through_capture else ()):
        table.add_column(col, overflow="fold")
    for r in rows:
        caught = "exactly" if r.exact else r.explain().split(": ", 1)[1]  # INCONCLUSIVEs too
        style = "" if r.exact else "bold red"
        cells = [r.fault, " ".join(r.declared), " ".join(r.flagged), caught]
        if r.capture is not None:
            cells.append("same verdicts" if not r.capture else f"{len(r.capture)} changed")
        table.add_row(*cells, style=style)
    console.print(table)
    exact = sum(r.exact for r in rows)
    console.print(f"{exact}/{len(rows)} faults caught by exactly their requirements")
    return EXIT_COMPLIANT if exact == len(rows) else EXIT_NON_COMPLIANT


def _combination_matrix(args: argparse.Namespace, console: Console) -> int:
    """``matrix --combinations N``: per combination its unexplained rows, then totals."""
    from .matrices.combinations import ComboRow

    if args.role == "recorder":
        from .matrices import recorder_combinations as combinations
    else:
        from .matrices import combinations  # type: ignore[no-redef]
    if args.all_pairs and (args.role != "recorder" or args.combinations is not None):
        error("error: --all-pairs runs every recorder pair: --role recorder, no --combinations")
        return EXIT_USAGE
    if (args.combinations is not None and args.combinations < 1) or args.jobs < 1:
        error("error: --combinations and --jobs must be 1 or more")
        return EXIT_USAGE
    seed = combinations.DEFAULT_SEED if args.seed is None else args.seed
    if args.all_pairs:
        combos = combinations.all_pairs()  # type: ignore[attr-defined]
    else:
        combos = combinations.sample(args.combinations, args.size, seed)
    status = make_console(stderr=True)

    def progress(done: int, total: int, row: ComboRow) -> None:
        status.print(f"[{done}/{total}] {row.explain()}", markup=False, highlight=False)

    drawn = "every composing pair" if args.all_pairs else f"seed {seed}"
    status.print(
        f"running the {args.role} suite once per combination ({drawn}, {len(combos)}), "
        f"{args.jobs} at a time..."
    )
    rows = combinations.combination_matrix(combos, args.jobs, progress)
    for r in rows:
        if r.clean:
            continue
        console.print(",".join(r.faults), markup=False, highlight=False)
        if r.refused:
            console.print(f"  INCONCLUSIVE, not run: {r.refused}", markup=False, highlight=False)
        for label, found in (
            ("unexpected", r.unexpected),
            ("missed FAIL", r.missed),
            ("ERROR", r.errors),
        ):
            for f in found:
                console.print(
                    f"  {label}: {f.requirement} {f.verdict}: {f.detail}",
                    markup=False,
                    highlight=False,
                )
    unexpected = sum(len(r.unexpected) for r in rows)
    missed = sum(len(r.missed) for r in rows)
    errors = sum(len(r.errors) for r in rows)
    clean = sum(r.clean for r in rows)
    refused = sum(bool(r.refused) for r in rows)
    console.print(
        f"{clean}/{len(rows)} combinations clean; {unexpected} unexpected FAIL/WARN, "
        f"{missed} missed FAIL, {errors} ERROR"
        + (f", {refused} INCONCLUSIVE (cannot be one sensor, not run)" if refused else "")
    )
    return EXIT_COMPLIANT if clean == len(rows) else EXIT_NON_COMPLIANT


#: The subcommands that stop at once on Ctrl-C (KeyboardInterrupt: exit 2, outputs whole or
#: absent); ``judge`` and ``verify`` run the suite, whose interrupts the guard turns into a
#: partial report.
SUBCOMMANDS = (
    "list", "faults", "matrix", "emulate", "export", "monitor", "calibrate", "diff", "plan"
)  # fmt: skip
#: what the main --help says of each subcommand (`sdi12-conform SUBCOMMAND --help`: the rest)
SUBCOMMAND_HELP = {
    "judge": "judge a recording: a run's transcript.jsonl or folder, a .sr, .vcd or .csv",
    "export": "write a saved run as a logic-analyzer capture (.sr, .vcd, .csv)",
    "list": "the requirement catalog with coverage (--role recorder: the recorder's)",
    "faults": "the emulator faults and what they break (--role recorder: the recorder's)",
    "matrix": "run the fault-detection matrix",
    "emulate": "serve the simulated sensor in real time over RFC 2217, TCP or a serial port",
    "monitor": "listen to a live bus (never transmits) and judge what was heard",
    "calibrate": "measure a real bench's timing before a long run",
    "diff": "what changed between two runs (exit 1 when anything got worse)",
    "verify": "check a run folder without the device: hashes, then the recording re-judged",
    "plan": "the test plan without touching the bus: cases, what they send, expected bus time",
    "rack": "many DUTs in one run from a rack file (rack FILE [options]; --port twice: the same)",
    "kit": "compile an Arduino sketch with the kit's core for the host and run the suite on it",
}


#: main() runs the main command in a process of its own (conformance.gc_pace)
_OWN_PROCESS = False


def main(argv: list[str] | None = None) -> int:
    """The program (``argv`` None: the process is ours to the end) or an in-process call."""
    whole_process = argv is None
    if not whole_process:
        GUARD.reset()  # an earlier in-process run's interrupt is not this one's
    GUARD.install()  # first of all: Ctrl-C from here on is recorded, never a traceback
    argv = list(sys.argv[1:] if argv is None else argv)
    if whole_process and not (argv and not argv[0].startswith("-")):
        # the main command's process: no collections outside its runs (conformance.gc_pace
        # turns the collector on for each run), none at all for a run in virtual time
        # (run_suite); a subcommand keeps it (emulate, monitor and calibrate run for as long
        # as the user wants)
        global _OWN_PROCESS
        _OWN_PROCESS = True
        gc.disable()
    try:
        code = _dispatch(argv)
    finally:
        if whole_process:
            GUARD.ignore_from_now()  # a Ctrl-C while Python shuts down must not exit 130
        else:
            GUARD.uninstall()
    if whole_process and not (argv and argv[0] in SUBCOMMANDS):
        _exit_at_once(code)
    return code


def _exit_at_once(code: int) -> None:
    """End a finished run's process without the interpreter's teardown: freeing a run's
    10^5 events, findings and modules one by one took about 0.15 s of a 1.4 s process, for
    nothing. Every report is written and closed by now; what Python would still do that
    matters is done here (the streams flushed, atexit handlers and finalizers run). Only
    with no other thread left that Python's exit would wait for; else the usual exit."""
    import atexit
    import contextlib
    import threading

    if any(
        t.is_alive() and not t.daemon
        for t in threading.enumerate()
        if t is not threading.current_thread()
    ):
        return
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # a closed pipe: nothing more to say
            stream.flush()
    os._exit(code)


def make_console(*, stderr: bool = False, plain: bool = False) -> Console:
    """A console for results (stdout) or errors (stderr). Off a terminal nothing is wrapped:
    a log or a pipe gets whole lines (rich would hard-wrap them at 80 columns). ``plain``:
    off a terminal, lines written as rich writes them there without importing rich
    (:mod:`conformance.reports.plain_console`; rich for anything more, on first need)."""
    stream = sys.stderr if stderr else sys.stdout
    if plain:
        from .reports.plain_console import PlainConsole, plain_output

        if plain_output(stream):
            plain_console = PlainConsole(
                lambda: make_console(stderr=stderr), lambda: _silence(plain_console, stream),
                stderr=stderr,
            )  # fmt: skip
            return cast("Console", plain_console)
    from rich.console import Console

    class RunConsole(Console):
        def on_broken_pipe(self) -> None:
            _silence(self, stream)

    return RunConsole(stderr=stderr, soft_wrap=not stream.isatty())


def _silence(console: Any, stream: TextIO) -> None:
    """The reader went away (``| head``): say nothing more there, but let the run finish and
    write its reports. rich's default ends the process with exit 1 from inside a pytest hook
    (an INTERNALERROR traceback and exit 3, the run cut off)."""
    console.quiet = True
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, stream.fileno())
    os.close(devnull)


def error(text: str) -> None:
    """One line for the user on stderr (never on stdout, where results and pipes go)."""
    make_console(stderr=True).print(text, style="red", markup=False, highlight=False)


def _main_command(argv: list[str], console: Console) -> int:
    """The main command: one DUT (:func:`run_suite`), a rack when it names several DUTs
    (:mod:`conformance.rack`), or several sensors on one line (``--address 0,1,3`` / ``all``:
    :mod:`conformance.commands.bus`)."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:
        return EXIT_COMPLIANT if exc.code == 0 else EXIT_USAGE
    from .options import is_bus
    from .rack.command import is_rack, rack_main

    baseline = getattr(args, "baseline", None)
    bus = is_bus(args.address)
    if bus or is_rack(argv, args):  # their tables and lines are rich's
        console = make_console()
    if is_rack(argv, args):  # --port twice or more, --rack, --tx: a rack
        if bus:
            error(
                "error: a rack runs one DUT per port: --address 0,1,3 / all (several sensors "
                "on one line) is for a run of one port"
            )
            return EXIT_USAGE
        return rack_main(argv, args, options_from_args(args), console)
    if bus:
        from .commands.bus import run_bus

        if baseline:
            error("error: --baseline compares the run of one sensor: give one --address")
            return EXIT_USAGE
        return run_bus(options_from_args(args), console, verbose=args.verbose)
    code, _ = run_suite(
        options_from_args(args), console, plan=args.plan, baseline=baseline, verbose=args.verbose
    )
    return code


def _dispatch(argv: list[str]) -> int:
    # the main command off a terminal writes plain lines without rich (a subcommand's
    # tables are rich's)
    console = make_console(plain=not (argv and argv[0] in SUBCOMMANDS))
    try:
        if argv and argv[0] in SUBCOMMANDS:
            if GUARD.requested:  # Ctrl-C while the program was starting
                return EXIT_INCOMPLETE
            GUARD.uninstall()  # subcommands stop on Ctrl-C at once (emulate runs until it)
        if argv and argv[0] == "list":
            return cmd_list(argv[1:], console)
        if argv and argv[0] == "faults":
            return cmd_faults(argv[1:], console)
        if argv and argv[0] == "matrix":
            return cmd_matrix(argv[1:], console)
        if argv and argv[0] == "emulate":
            from .emulator_server.command import emulate_main

            return emulate_main(argv[1:])
        if argv and argv[0] == "export":
            from .offline.export import export_main

            return export_main(argv[1:])
        if argv and argv[0] == "judge":
            return cmd_judge(argv[1:], console)
        if argv and argv[0] == "monitor":
            from .monitor.command import monitor_main

            return monitor_main(argv[1:], console, cmd_judge)
        if argv and argv[0] == "diff":
            from .commands.diff import diff_main

            return diff_main(argv[1:], console)
        if argv and argv[0] == "plan":
            from .commands.plan import plan_main

            return plan_main(argv[1:])
        if argv and argv[0] == "verify":
            from .commands.verify import verify_main

            return verify_main(argv[1:], console, cmd_judge)
        if argv and argv[0] == "rack":  # rack FILE ...: the main command's --rack FILE ...
            from .rack.command import rack_argv

            given = rack_argv(argv[1:], console)
            return given if isinstance(given, int) else _main_command(given, console)
        if argv and argv[0] == "kit":
            from .commands.kit import kit_main

            return kit_main(argv[1:], main)  # the run itself, with its own Ctrl-C guard
        if argv and argv[0] == "calibrate":
            from .calibrate import calibrate_main

            return calibrate_main(argv[1:])
        if argv and not argv[0].startswith("-"):  # a word where a subcommand goes
            from .suggest import did_you_mean

            error(
                f"error: no subcommand {argv[0]!r}{did_you_mean(argv[:1], SUBCOMMAND_HELP)}; "
                "the main command takes options only (sdi12-conform --help)"
            )
            error(subcommands_text().rstrip())
            return EXIT_USAGE
        return _main_command(argv, console)
    except SystemExit as exc:  # argparse of a subcommand: --help (0) or a usage error (2)
        return EXIT_COMPLIANT if exc.code in (0, None) else EXIT_USAGE
    except KeyboardInterrupt:
        error("interrupted")
        return EXIT_INCOMPLETE
    except Exception as exc:  # a bug in the tool: say so plainly, exit 3 for CI
        error(f"internal error: {type(exc).__name__}: {exc}")
        error("please report this with the command line that caused it")
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
