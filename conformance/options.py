"""The run's options, spelled once: the command line and the pytest plugin register from here.

Each :class:`Option` holds what both need: the name (``--echo`` on the command line,
``--sdi12-echo`` in pytest), type, default, choices, help and the check that refuses a value
the tool cannot use. ``sdi12-conform`` turns its parsed values into a
:class:`~conformance.run.RunOptions` with :func:`cli_values` and hands that object to
:func:`conformance.conduct.conduct`; a plain ``pytest --sdi12-...`` run reads the plugin's
flags with :func:`run_option_values`, so an option added to :data:`OPTIONS` reaches the run
on both paths. Imported by ``sdi12-conform --help``: nothing heavy here.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from .declaration import address_problem
from .profiles import PROFILES

ROLES = ("sensor", "recorder")


class UsageError(ValueError):
    """A setting the tool cannot use; the message says what to do instead."""


def check_address(text: str | None, where: str = "--address") -> None:
    """An invalid address would go onto the bus (``00I!``) and look like a silent device.
    The command line also takes several (``0,1,3``) or ``all``: a bus of sensors, each judged
    in turn (:func:`bus_addresses`); one pytest run judges one DUT."""
    if text is not None and where == "--address" and is_bus(text):
        bus_addresses(text, where)
        return
    problem = None if text is None else address_problem(text)
    if problem:
        raise UsageError(f"{where}: {problem}")


#: ``--address all``: every sensor on the line, found by trying each address.
ALL = "all"


def is_bus(text: str | None) -> bool:
    """Whether ``--address`` names a bus of sensors (``0,1,3`` or ``all``), not one."""
    return text is not None and (text.strip() == ALL or "," in text)


def bus_addresses(text: str, where: str = "--address") -> tuple[str, ...] | None:
    """``0,1,3`` -> ('0', '1', '3'), each checked, none twice; ``all`` -> None (found by
    trying each address)."""
    if text.strip() == ALL:
        return None
    addresses = tuple(a.strip() for a in text.split(","))
    for address in addresses:
        problem = address_problem(address)
        if problem:
            raise UsageError(f"{where}: {problem} (in {text!r})")
    twice = sorted({a for a in addresses if addresses.count(a) > 1})
    if twice:
        raise UsageError(f"{where}: address {', '.join(twice)} named twice in {text!r}")
    return addresses


def check_uncertainty(ms: float | None, where: str = "--timing-uncertainty-ms") -> None:
    """A stamp uncertainty is a non-negative width; a negative one would tighten every limit."""
    if ms is not None and not ms >= 0:  # `not >=` also rejects NaN
        raise UsageError(f"{where} must be 0 or more milliseconds, not {ms:g}")


def check_job_timeout(seconds: float | None, where: str = "--job-timeout") -> None:
    """A job's budget is a positive time; 0 or less would cut every job before it began."""
    if seconds is not None and not seconds > 0:  # `not >` also rejects NaN
        raise UsageError(f"{where} must be more than 0 seconds, not {seconds:g}")


def check_sweep(text: str | None, where: str = "--sweep") -> None:
    """``--sweep`` names the sweeps (reply, wake); an unknown one would silently run none."""
    names = [n.strip() for n in (text or "").split(",") if n.strip()]
    unknown = [n for n in names if n not in SWEEPS]
    if unknown or (text is not None and not names):
        raise UsageError(
            f"{where} takes {', '.join(SWEEPS)} or both comma-separated (got {text!r})"
        )


#: The recorder role's tolerance sweeps (conformance.recorder.sweep), named here so that
#: ``--help`` stays light.
SWEEPS = ("reply", "wake")

_UNSET = object()


@dataclass(frozen=True)
class Option:
    """One option of a conformance run, for both the command line and pytest."""

    name: str  # the command line's, without dashes: "sdi-version" -> --sdi-version
    field: str  # the RunOptions attribute it sets
    help: str
    default: Any = None
    choices: tuple[str, ...] | None = None
    type: Callable[[str], Any] | None = None
    flag: bool = False  # store_true
    repeat: bool = False  # append: given once per value
    metavar: str | None = None
    #: the value of an option given without one (``--sweep`` alone); None: a value is due
    const: Any = None
    plugin_name: str | None = None  # pytest's name without "--sdi12-", if not ``name``
    plugin_help: str | None = None  # where pytest's wording must differ (its default)
    cli_default: Any = _UNSET  # the command line's default, if not ``default``
    check: Callable[[Any, str], None] | None = None  # (value, option as typed): UsageError

    @property
    def cli_flag(self) -> str:
        return f"--{self.name}"

    @property
    def plugin_flag(self) -> str:
        return f"--sdi12-{self.plugin_name or self.name}"

    @property
    def plugin_dest(self) -> str:
        return self.plugin_flag.removeprefix("--").replace("-", "_")

    @property
    def cli_dest(self) -> str:
        return self.name.replace("-", "_")

    def _kwargs(self, default: Any) -> dict[str, Any]:
        if self.flag:
            return {"action": "store_true", "default": bool(default)}
        kwargs: dict[str, Any] = {"default": [] if self.repeat else default}
        if self.repeat:
            kwargs["action"] = "append"
        for key in ("choices", "type", "metavar"):
            if getattr(self, key) is not None:
                kwargs[key] = getattr(self, key)
        if self.const is not None:
            kwargs["nargs"], kwargs["const"] = "?", self.const
        return kwargs

    def add_to_cli(self, parser: argparse.ArgumentParser) -> None:
        default = self.default if self.cli_default is _UNSET else self.cli_default
        parser.add_argument(self.cli_flag, help=self.help, **self._kwargs(default))

    def add_to_pytest(self, group: Any) -> None:
        group.addoption(
            self.plugin_flag, help=self.plugin_help or self.help, **self._kwargs(self.default)
        )


OPTIONS: tuple[Option, ...] = (
    Option(
        "port",
        "port",
        "a serial port (/dev/ttyUSB0, COM3), a pyserial URL (rfc2217://HOST:PORT), "
        "'exec:PROGRAM ARGS' or unix:PATH (a harness, docs/harness-protocol.md), "
        "replay:PATH (a saved run played back), or "
        "sim / sim://?faults=a,b&version=1.3 for the built-in simulated device "
        "(default: sim, said loudly when used)",
        default="sim",
        cli_default=None,  # the command line says loudly that it judges the simulated device
    ),
    Option(
        "role",
        "role",
        "what the device under test is; the tool plays the other side (default: sensor)",
        default="sensor",
        choices=ROLES,
    ),
    Option(
        "address",
        "address",
        "DUT address (default: the declaration, else ask with ?!); several sensors on one "
        "line: 0,1,3 or all (each judged in turn into sensor-<a>/, then the bus cases; all "
        "tries a! at each of the 62 addresses, never ?!)",
        check=check_address,
    ),
    Option(
        "sdi-version",
        "version",
        "force the rule set, 1.3 or 1.4 (default: from aI!)",
        plugin_name="version",
    ),
    Option(
        "declaration",
        "declaration",
        "TOML file declaring the DUT's address and features (recorder role: its "
        "[recorder] table of the command kinds, addresses and measurements it can do)",
    ),
    Option(
        "report-dir",
        "report_dir",
        "output folder (default: reports/<date>-<role>)",
        plugin_help="where verdicts.json, report.html and the transcript go "
        "(default: reports/<date>-<role>)",
    ),
    Option("strict", "strict", "WARN (SHOULD violations) fails too", flag=True),
    Option(
        "timing-uncertainty-ms",
        "timing_uncertainty_ms",
        "widen the timestamp uncertainty the link measures (it can never narrow it)",
        type=float,
        check=check_uncertainty,
    ),
    Option(
        "echo",
        "echo",
        "real links: does the interface echo the tool's own characters "
        "(default auto: found out on the first transmission)",
        default="auto",
        choices=("auto", "on", "off"),
    ),
    Option(
        "direction",
        "direction",
        "real links: raise this line for exactly the tool's transmissions "
        "(an RS-485-style transceiver's driver enable)",
        default="none",
        choices=("none", "rts", "dtr"),
    ),
    Option(
        "trigger",
        "trigger",
        "recorder role: shell command run per scenario with the request in SDI12_* "
        "environment variables (exit 0: done; exit 3: this logger cannot do this job, "
        "N/A where only an optional rule asks for it, else a FAIL), or 'interactive' to "
        "prompt an operator",
    ),
    Option(
        "job-timeout",
        "job_timeout",
        "recorder role: bus seconds each scenario's job may take before it is cut and what "
        "the recorder sent until then is judged (default per scenario: 30 s, plus 10 s and "
        "the played sensor's longest ttt for each command asked; stated in the report and "
        "in SDI12_TIMEOUT_S)",
        type=float,
        metavar="S",
        check=check_job_timeout,
    ),
    Option(
        "sweep",
        "sweep",
        "recorder role: after the suite, a tolerance sweep: one short job (aM!, aD0!) per "
        "step on a sensor that starts its replies later and later (reply: 0-100 ms extra in "
        "5 ms steps, and the 15.40 ms limit of R-7.0-10) or hears commands later and later "
        "after a break (wake: 0-150 ms in 5 ms steps; R-7.0-07 allows 100 ms); shows where "
        "the recorder stops coping and flags it inside the standard's limit, never changes a "
        "verdict. Costs one job per step on a real logger. Given alone: both",
        const="reply,wake",
        metavar="reply,wake",
        check=check_sweep,
    ),
    Option(
        "profile",
        "profile",
        "sensor role: a named short selection instead of the whole suite; production: an "
        "end-of-line test (identification, address, one measurement of each kind with its "
        "CRC, the timing windows), its report folder named by the sensor's serial number",
        choices=tuple(PROFILES),
    ),
    Option(
        "req",
        "requirements",
        "a partial run: only cases judging this requirement ID (R-4.4.6-02) or clause "
        "(4.4.12); repeatable",
        repeat=True,
        metavar="ID_OR_CLAUSE",
    ),
)


def add_cli_options(parser: argparse.ArgumentParser, names: Iterable[str]) -> None:
    """Add the named options (in that order) to the command line's parser."""
    by_name = {o.name: o for o in OPTIONS}
    for name in names:
        by_name[name].add_to_cli(parser)


def add_pytest_options(group: Any) -> None:
    for option in OPTIONS:
        option.add_to_pytest(group)


def check_values(values: dict[str, Any], *, plugin: bool) -> None:
    """Run each option's own check on ``values`` (RunOptions field -> value)."""
    for option in OPTIONS:
        if option.check is not None:
            where = option.plugin_flag if plugin else option.cli_flag
            option.check(values.get(option.field), where)


def cli_values(args: argparse.Namespace) -> dict[str, Any]:
    """RunOptions field -> value, from the command line's parsed arguments."""
    return {option.field: getattr(args, option.cli_dest) for option in OPTIONS}


def run_option_values(getoption: Callable[[str], Any]) -> dict[str, Any]:
    """RunOptions field -> value, read from pytest's parsed options."""
    values = {option.field: getoption(option.plugin_dest) for option in OPTIONS}
    values["requirements"] = tuple(values["requirements"] or ())
    return values
