"""The recorder role's side of every kind of port: the line the played sensors go on, and who
the recorder under test is.

:mod:`conformance.links.registry` keeps one opener per role for each kind of port; the
recorder-role ones build played-sensor buses and recorder drivers, which sit in this layer,
so they are attached here (:func:`~conformance.links.registry.attach_recorder_role`) and the
registry stays the one place that chooses between kinds:

- ``sim`` / ``sim://?recorder-faults=NAME&recorder=module:callable``: the virtual-time sim
  bus, the golden recorder (with one or more faults) or a named program in this process;
- ``exec:PROGRAM`` / ``unix:PATH``: a recorder harness, on the same virtual-time bus;
- ``replay:FOLDER``: a saved recorder-role run, its recorder played back from the recording;
- ``rfc2217-serve://HOST:PORT``: the played sensors served in real time; the recorder
  (in-process over its own RFC 2217 connection, or an external one told ``SDI12_PORT``)
  connects to them.

Every other kind (a serial device, ``rfc2217://``...) has no recorder-role opener: the
recorder role plays the sensors itself, so it needs a bus it can put them on.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass

from .. import ports
from ..links.base import BusEnd, LinkInfo
from ..links.errors import PortError
from ..links.registry import PortOptions, attach_recorder_role, find, kinds
from ..replay.link import open_recorder_replay, replayed_info
from ..replay.recording import RecordingError
from ..sim.bus import SimBus, SimLink
from ..sim.line_monitor import LineMonitor
from ..suggest import did_you_mean
from .drivers import Driver, InProcess
from .faults import RECORDER_FAULTS, composition_conflict, faulty_recorder
from .harness_driver import HarnessRecorder
from .replay_driver import RecordedRecorder
from .served_line import ServedLine, parse_served


@dataclass
class RecorderLine:
    """A port opened for the recorder role. ``link`` is what the reports read as the run's
    link: the tool's end of the sim bus, or the served line; ``bus`` the sim bus the played
    sensors go on (None when they are served in real time, on ``served``)."""

    link: BusEnd
    driver: Driver
    faults: tuple[str, ...] = ()  # the golden recorder's faults (?recorder-faults=)
    bus: SimBus | None = None
    served: ServedLine | None = None


def open_recorder_line(port: str, options: PortOptions, driver: Driver | None) -> RecorderLine:
    """Open ``port`` for the recorder role with the kind's own opener; ``driver`` is the
    recorder the user named (``--trigger``), None for the one the port implies. The user's
    timing uncertainty is applied here, whatever the kind."""
    kind = find(port)
    if kind.open_recorder_role is None:
        hints = [k.recorder_role_hint for k in kinds() if k.open_recorder_role]
        takes = ", ".join(hints[:-1]) + " or " + hints[-1]
        raise PortError(f"port {port!r}: the recorder role plays the sensors itself: use {takes}")
    line: RecorderLine = kind.open_recorder_role(port, options, driver)
    line.link.widen(options.timing_uncertainty)
    return line


def load_program(path: str) -> Callable:
    """``package.module:callable`` -> the callable (a recorder program or a factory)."""
    module, _, name = path.partition(":")
    if not module or not name:
        raise PortError(f"recorder program {path!r} is not 'package.module:callable'")
    try:
        obj = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as exc:
        raise PortError(f"cannot load recorder program {path!r}: {exc}") from exc
    return obj


def recorder_faults(extra: dict[str, str]) -> tuple[str, ...]:
    """The golden-recorder faults a port's ``recorder-faults=`` names (PortError if one is
    unknown, or if they cannot be one recorder: two that change one thing apart)."""
    faults = tuple(f for f in extra.get("recorder-faults", "").split(",") if f)
    unknown = [f for f in faults if f not in RECORDER_FAULTS]
    if unknown:
        hint = did_you_mean(unknown, RECORDER_FAULTS)
        named = ", ".join(repr(f) for f in unknown)
        raise PortError(
            f"recorder-faults: {named} {'is' if len(unknown) == 1 else 'are'} not a recorder "
            f"fault{hint}; it takes one or more of: {_known_faults()} (got "
            f"{','.join(faults)}); `sdi12-conform faults --role recorder` describes them"
        )
    clash = composition_conflict(faults)
    if clash:
        raise PortError(f"recorder-faults={','.join(faults)} do not compose: {clash}")
    return faults


def _known_faults() -> str:
    return ", ".join(sorted(RECORDER_FAULTS))


def _in_process(extra: dict[str, str], faults: tuple[str, ...]) -> Driver:
    """The recorder a port names for this process: ``recorder=`` or the golden one."""
    program = extra.get("recorder")
    return InProcess(load_program(program)() if program else faulty_recorder(faults))


def _refuse_outside(driver: Driver) -> None:
    """A recorder acting outside this process cannot reach a virtual-time bus."""
    if driver.needs_real_time:
        raise PortError(
            f"a {driver.kind} recorder acts outside this process and cannot reach the "
            "simulated bus; serve the played sensors in real time with "
            "--port rfc2217-serve://127.0.0.1:0 (the recorder connects to SDI12_PORT)"
        )


def _sim_line(driver: Driver, faults: tuple[str, ...] = ()) -> RecorderLine:
    bus = SimBus([LineMonitor()])
    return RecorderLine(SimLink(bus), driver, faults, bus=bus)


def _open_sim(port: str, options: PortOptions, driver: Driver | None) -> RecorderLine:
    spec = ports.parse_sim(port)
    if spec.faults:
        raise PortError(
            "sim://?faults= breaks the simulated sensor judged in the sensor role; in the "
            f"recorder role use sim://?recorder-faults=NAME ({_known_faults()})"
        )
    if spec.sensors:
        raise PortError(
            "sim://?sensors= puts several simulated sensors on the line to judge them (the "
            "sensor role, --address 0,1,3); the recorder role plays its own sensors"
        )
    extra = spec.extra
    faults = recorder_faults(extra)
    if driver is None:
        driver = _in_process(extra, faults)
    _refuse_outside(driver)
    return _sim_line(driver, faults)


def _open_harness(port: str, options: PortOptions, driver: Driver | None) -> RecorderLine:
    if driver is None:
        harness = HarnessRecorder(port)
        harness.probe()
        driver = harness
    _refuse_outside(driver)
    line = _sim_line(driver)
    # the reports name the harness link, still virtual time; a version-2 harness (a kit)
    # gives each frame's own length, so the recorder's bit rate is observed
    timed = getattr(driver, "version", 1) >= 2
    line.link.info = LinkInfo(
        kind=port.partition(":")[0], virtual_time=True, bit_timing=timed, frame_lengths=timed
    )
    return line


def _open_replay(port: str, options: PortOptions, driver: Driver | None) -> RecorderLine:
    try:
        recording = open_recorder_replay(port)
    except RecordingError as exc:
        raise PortError(str(exc)) from exc
    line = _sim_line(RecordedRecorder(recording.events))
    line.link.info = replayed_info(recording)  # the recorded run's link, as it was
    return line


def _open_served(port: str, options: PortOptions, driver: Driver | None) -> RecorderLine:
    spec = parse_served(port)
    faults = recorder_faults(spec.extra)
    if driver is None:
        driver = _in_process(spec.extra, faults)
    served = ServedLine(spec, options.timing_uncertainty)
    environment = getattr(driver, "environment", None)
    if environment is not None:  # an external recorder is told where to connect
        environment["SDI12_PORT"] = served.url
    return RecorderLine(served, driver, faults, served=served)


attach_recorder_role("sim", _open_sim, "--port sim (virtual time)")
for _name, _hint in (
    ("exec", "--port 'exec:PROGRAM ARGS' (a recorder harness, virtual time)"),
    ("unix", "--port unix:PATH (a recorder harness on a socket, virtual time)"),
):
    attach_recorder_role(_name, _open_harness, _hint)
attach_recorder_role("replay", _open_replay, "--port replay:FOLDER (a saved recorder-role run)")
attach_recorder_role(
    "rfc2217-serve",
    _open_served,
    "--port rfc2217-serve://127.0.0.1:0 (served in real time, the recorder connects over RFC 2217)",
)
