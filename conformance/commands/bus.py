"""A live run of several sensors on one line (issue 23, item 2): ``--address 0,1,3`` or
``--address all``.

First the bus is looked at, before anything is judged (:mod:`conformance.sensor.bus_discovery`):
the named sensors each answer ``a!`` (``all``: one ``a!`` at each of the 62 addresses, never
``?!``), and ``aI!``. Two sensors at one address are a bus fault: the run says so and stops
with exit 4 (a setup the tool cannot judge: every reply at that address is two sensors'),
writing nothing but ``bus.json``. A named address nothing answers at stops it with exit 5.

Then the sensor suite runs once per sensor on the same port, each into ``<run>/sensor-<a>/``
as passive judging lays a bus out (``duts`` in each verdicts.json naming every sensor), with the
bus cases (``testcases/sensor/test_bus.py``) judged in each sensor's own folder: a bus case is
about what that sensor did while the others talked. The console ends with one line per
sensor; the exit code is the worst of the runs.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..exits import EXIT_INCOMPLETE, EXIT_INTERNAL, EXIT_NO_DEVICE, EXIT_USAGE, say_error
from ..interrupts import GUARD
from ..run import RunOptions
from .passive import print_sensors, worst_exit

if TYPE_CHECKING:
    from rich.console import Console

    from ..sensor.bus_discovery import BusDiscovery

#: What a run of the whole bus writes beside the sensors' folders.
BUS_FILE = "bus.json"


def discovery_json(found: BusDiscovery, asked: str, bus_s: float) -> dict[str, Any]:
    """``bus.json``: what the probes found, before anything was judged."""
    return {
        "asked": asked,
        "probes": len(found.exchanges),
        "bus_s": round(bus_s, 3),
        "sensors": [
            {"address": s.address, "identification": s.identification} for s in found.found
        ],
        "duplicates": [{"address": a, "why": why} for a, why in found.duplicates],
        "silent": list(found.silent),
    }


def look_at_the_bus(options: RunOptions, folder: Path, console: Console) -> BusDiscovery | int:
    """Open the port, probe the addresses ``options.address`` names, close it; the
    discovery, or the exit code of a setup that cannot be judged (said on stderr)."""
    from ..links.errors import PortError
    from ..options import bus_addresses
    from ..ports import open_port
    from ..sensor.bus_discovery import ALL_ADDRESSES, discover_bus

    assert options.address is not None
    named = bus_addresses(options.address)
    try:
        opened = open_port(options.port, echo=options.echo, direction=options.direction,
                           timing_uncertainty=options.timing_uncertainty)  # fmt: skip
    except PortError as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    link = opened.link
    if named is None:
        console.print(
            f"looking for sensors on {options.port}: a! at each of the {len(ALL_ADDRESSES)} "
            "addresses (never ?!)",
            markup=False,
            highlight=False,
        )  # fmt: skip
    try:
        found = discover_bus(link, named or ALL_ADDRESSES, sweep=named is None)
        bus_s = link.now()
    finally:
        link.close()
    folder.mkdir(parents=True, exist_ok=True)
    record = discovery_json(found, options.address, bus_s)
    (folder / BUS_FILE).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    return _refusal(found, named, folder) or found


def _refusal(found: BusDiscovery, named: tuple[str, ...] | None, folder: Path) -> int | None:
    """The exit code of a bus that cannot be judged (said on stderr), or None."""
    for _address, why in found.duplicates:
        say_error(f"bus fault: {why} (a duplicate address); nothing judged ({folder / BUS_FILE})")
    if found.duplicates:
        return EXIT_USAGE
    if named is not None and found.silent:
        say_error(
            f"error: nothing answered a! at {', '.join(found.silent)} of --address "
            f"{','.join(named)}: check wiring, power and addresses; nothing judged"
        )
        return EXIT_NO_DEVICE
    if not found.found:
        say_error("error: no sensor answered a! at any address; nothing judged")
        return EXIT_NO_DEVICE
    return None


def run_bus(options: RunOptions, console: Console, *, verbose: bool = False) -> int:
    """The whole bus: discovery, then the suite once per sensor (see the module's text)."""
    from ..options import UsageError, check_values
    from ..report_folder import run_folder

    try:
        check_values(vars(options), plugin=False)  # refused before anything goes on the bus
    except UsageError as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    if options.role != "sensor":
        say_error("error: --address 0,1,3 / all judges the sensors of a bus (--role sensor)")
        return EXIT_USAGE
    if options.port is None:
        options.port = "sim"
        console.print(
            "note: no --port given: judging the built-in SIMULATED bus (sim, one sensor: "
            "use sim://?sensors=0,1,3 for several)",
            style="bold yellow",
            markup=False,
        )
    base = run_folder(options.report_dir, "bus")
    found = look_at_the_bus(options, base, console)
    if isinstance(found, int):
        return found
    if GUARD.requested:  # Ctrl-C while the bus was looked at: nothing judged yet
        GUARD.close()
        say_error(f"interrupted while looking at the bus: nothing judged ({base / BUS_FILE})")
        return EXIT_INCOMPLETE
    bus = tuple((s.address, s.identification) for s in found.found)
    alone = len(bus) == 1
    console.print(
        f"{len(bus)} sensor(s) on the bus ({', '.join(a for a, _ in bus)}), each a DUT"
        + ("; one alone: no bus cases" if alone else "; then the bus cases in each one's run"),
        markup=False,
        highlight=False,
    )
    return _run_sensors(options, bus, base, console, verbose, alone)


def _run_sensors(
    options: RunOptions,
    bus: tuple[tuple[str, str | None], ...],
    base: Path,
    console: Console,
    verbose: bool,
    alone: bool,
) -> int:
    """The suite once per sensor, in address order; the worst exit code."""
    from ..conduct import conduct
    from ..reports.console import ProgressPlugin, print_summary

    codes: list[int] = []
    done: list[tuple[str | None, dict[str, Any], Path]] = []
    for n, (address, _ident) in enumerate(bus):
        if n:
            GUARD.reset()  # the last sensor's run closed the guard: this one starts afresh
        folder = base / f"sensor-{address}"
        one = replace(options, address=address, report_dir=str(folder), bus=() if alone else bus)
        plugins: list[object] = [] if verbose else [ProgressPlugin(console)]
        result = conduct(one, verbose=verbose, plugins=plugins)
        data = result.document
        if data is None:
            if GUARD.requested:
                return EXIT_INCOMPLETE
            say_error(f"error: sensor {address} was not judged (pytest exit {result.pytest_code})")
            return EXIT_INTERNAL
        console.print(f"sensor {address}:", style="bold", markup=False, highlight=False)
        print_summary(console, data, str(folder))
        code = result.exit_code
        codes.append(code if code is not None else result.pytest_code)
        done.append((address, data, folder))
        if GUARD.requested:  # Ctrl-C: this sensor's report says so; the next is not begun
            GUARD.close()
            return EXIT_INCOMPLETE
    GUARD.close()  # every sensor judged: a later Ctrl-C leaves the reports alone
    print_sensors(console, done)
    return worst_exit(codes)


__all__ = ["BUS_FILE", "run_bus"]
