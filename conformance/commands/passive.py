"""Passive judging: every rule that traffic alone can show, on a recording no tool drove.

``judge_passively`` checks the recording can be read (a clear one-line error and exit 4 if
not, or if it holds no SDI-12 traffic), then runs the passive cases (``testcases.passive``)
once per role over the port ``recording:PATH?...``: the sensor rules aggregate as role
``sensor``, the recorder rules as role ``recorder``. ``--role both`` writes two report sets,
``<report-dir>/sensor/`` and ``<report-dir>/recorder/``, prints both verdicts and exits with
the worse of the two codes.

Every sensor on the bus is a DUT (issue 23): when the recording shows replies from several
sensor addresses and no ``--address`` narrows it, the sensor rules run once per address into
``<report-dir>/sensor-<a>/`` (the recorder rules into ``<report-dir>/recorder/``), the console
ends with one line per sensor, and the exit code is the worst of them all.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import gc_pace
from ..capture.heap import give_back_freed_heap
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
    from ..offline.heard import bus_of

    link = recording_of(port)
    events = link.transcript.events
    # the commands' kinds from the bus pass every later step reads (no whole-run view: one
    # held from here held ~12 MB at an hour's capture to the end, issue 22), and whether a
    # break was heard, asked before any list of the events is made
    kinds = bus_of(link).kinds
    # any text ending in '!' parses as an extended command: alone it is no sign of SDI-12
    if any(k is not Kind.EXTENDED for k in kinds) or (
        kinds and any(e.kind is EventKind.BREAK for e in events)
    ):
        return None
    chars = [e for e in events if e.kind is EventKind.CHAR]
    breaks = [e for e in events if e.kind is EventKind.BREAK]
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


@dataclass(frozen=True)
class RoleJob:
    """One run of the passive cases: whose rules (``role``), narrowed to which sensor
    (``address``; None: all), into which folder, and the label the console gives it."""

    label: str
    role: str
    address: str | None
    report_dir: Path
    of_bus: bool = False  # one of several sensors on the bus, each judged as a DUT


def sensors_heard(port: str) -> list[str]:
    """The addresses of the sensors the recording shows replies from, in address order
    (a sensor moved by ``aAb!`` counted once, at its first address)."""
    from ..offline.fixtures import recording_of
    from ..offline.heard import bus_sensors

    return [s.address for s in bus_sensors(recording_of(port))]


def role_jobs(roles: tuple[str, ...], base: Path, args: PassiveJob, port: str) -> list[RoleJob]:
    """The runs to make. Every sensor on the bus is a DUT: with replies from more than one
    address and no ``--address``, the sensor rules run once per address, each narrowed as
    ``--address`` narrows them, into ``<base>/sensor-<a>/`` (the recorder rules, if asked
    for, into ``<base>/recorder/``). One sensor keeps one folder per role, as before."""
    addresses = sensors_heard(port) if "sensor" in roles and args.address is None else []
    several = len(addresses) > 1
    jobs: list[RoleJob] = []
    for role in roles:
        if role == "sensor" and several:
            jobs += [RoleJob(f"sensor {a}", role, a, base / f"sensor-{a}", True) for a in addresses]
            continue
        folder = base / role if len(roles) > 1 or several else base
        jobs.append(RoleJob(role, role, args.address if role == "sensor" else None, folder))
    return jobs


def judge_passively(args: PassiveJob, console: Console) -> int:
    """Judge the recording ``args`` names; the exit code is the worst run's."""
    from ..declaration import DeclarationError, normalise_version

    port = recording_port(
        args.recording, args.format, channel=args.channel, tx_channel=args.tx_channel,
        invert=args.invert, baud=args.baud, glitch_filter_us=args.glitch_filter_us,
        force=args.force,
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
    give_back_freed_heap()  # the bus pass made and let go of more than it kept
    roles = ROLES if args.role == "both" else (args.role,)
    jobs = role_jobs(roles, run_folder(args.report_dir, "passive"), args, port)
    sensors = [j.address for j in jobs if j.of_bus]
    if sensors:  # judged one by one: no run holds every sensor's records (issue 22)
        from ..offline.fixtures import recording_of
        from ..offline.heard import settle_bus

        settle_bus(recording_of(port))
        give_back_freed_heap()  # and so did the pre-scans of the sensors on the bus
    console.print(
        f"judging {args.recording} passively: the rules its traffic can show "
        f"({' and '.join(roles)} rules)"
        + (f"; {len(sensors)} sensors on the bus ({', '.join(map(str, sensors))}), each a DUT"
           if sensors else ""),
        markup=False,
        highlight=False,
    )  # fmt: skip
    code = _run_jobs(jobs, port, args, console)
    forget(port)
    return code


def _run_jobs(jobs: list[RoleJob], port: str, args: PassiveJob, console: Console) -> int:
    """Each job in turn, its summary printed; then one line per sensor when there were
    several. The exit code is the worst of all (an internal error first)."""
    from ..exits import EXIT_INCOMPLETE, EXIT_INTERNAL
    from ..reports.console import print_summary

    codes: list[int] = []
    done: list[tuple[RoleJob, dict[str, Any]]] = []
    with gc_pace.runs_over_held_data() as collect:  # each run's garbage freed before the next
        for i, job in enumerate(jobs):
            code, data = _run_one(i, jobs, port, args, console, collect)
            if GUARD.requested and data is None:  # Ctrl-C before this run wrote its verdicts
                return EXIT_INCOMPLETE
            if data is None:  # the run wrote no verdicts (its own, never a file's)
                if code in (EXIT_USAGE, EXIT_INTERNAL):
                    return code
                error(f"error: the {job.label} rules were not judged (pytest exit {code})")
                return EXIT_INTERNAL
            console.print(f"{job.label} rules:", style="bold", markup=False, highlight=False)
            print_summary(console, data, str(job.report_dir))
            codes.append(code)
            done.append((job, data))
            if GUARD.requested:  # Ctrl-C: this run's report says so; the next one is not begun
                GUARD.close()
                return EXIT_INCOMPLETE
    print_sensors(console, [(j.address, d, j.report_dir) for j, d in done if j.of_bus])
    return worst_exit(codes)


def _run_one(
    i: int, jobs: list[RoleJob], port: str, args: PassiveJob, console: Console,
    collect: Callable[[], None],
) -> tuple[int, dict[str, Any] | None]:  # fmt: skip
    """Job ``i``'s run; then what no later job reads is let go: its session, the records
    only it read (:func:`release`) and its run's cyclic garbage (``collect``). Gives the
    run's exit code (its own if it made one, pytest's otherwise) and its verdicts (None: it
    wrote none)."""
    result = _run_role(jobs[i], port, args, console)
    code, data = result.pytest_code, result.document
    if result.run is not None:
        # its session (its share of the records) is held by the run's pytest objects,
        # cyclic garbage (freed by collect() below, or by the next full collection)
        result.run.session = None
    release(port, jobs[i + 1 :])
    collect()
    if data is not None and result.exit_code is not None:
        code = result.exit_code
    return code, data


def release(port: str, later: list[RoleJob]) -> None:
    """Drop the loaded recording's rebuilt records that none of the ``later`` runs reads
    (:func:`~conformance.offline.heard.release_records`): each sensor's once it is judged,
    all of them before the recorder's run, so that run's peak does not hold them. Nothing
    when a later run judges every sensor together (no ``--address``, one sensor)."""
    from ..offline.fixtures import _LOADED
    from ..offline.heard import release_records

    link = _LOADED.get(port)
    sensors = [j.address for j in later if j.role == "sensor"]
    if link is None or None in sensors:
        return
    release_records(link, {a for a in sensors if a is not None})


def worst_exit(codes: list[int]) -> int:
    """The exit code of several runs: an internal error first, then a usage error, a FAIL,
    an incomplete run, and compliant only if every run was."""
    from ..exits import EXIT_INCOMPLETE, EXIT_INTERNAL, EXIT_NON_COMPLIANT

    order = (EXIT_INTERNAL, EXIT_USAGE, EXIT_NON_COMPLIANT, EXIT_INCOMPLETE, EXIT_COMPLIANT)
    return min(codes, key=lambda c: order.index(c) if c in order else -1)


def print_sensors(console: Console, done: list[tuple[str | None, dict[str, Any], Path]]) -> None:
    """One line per sensor of a bus: address, identification, verdict, report folder (the
    passive judging of a recording and a live bus run alike)."""
    if not done:
        return
    console.print("sensors on the bus:", style="bold", markup=False, highlight=False)
    for address, data, folder in done:
        ident = (data["dut"].get("identification") or "(no aI! reply seen)").strip()
        console.print(
            f"  sensor {address} · {ident!r} · {data['summary']['verdict']} · {folder}",
            markup=False,
            highlight=False,
        )


def _run_role(job: RoleJob, port: str, args: PassiveJob, console: Console) -> RunResult:
    """One job's rules: the passive cases over the recording's port, aggregated as its role."""
    from ..reports.console import ProgressPlugin

    options = RunOptions(
        port=port,
        role=job.role,
        report_dir=str(job.report_dir),
        address=job.address,
        version=args.sdi_version,
        strict=args.strict,
    )
    return conduct(options, cases="testcases.passive", plugins=[ProgressPlugin(console)])


__all__ = ["EXIT_COMPLIANT", "judge_passively"]
