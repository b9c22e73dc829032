"""Turn a ``--port`` string into a link.

``sim`` / ``sim://?faults=a,b&version=1.3&address=0`` is the built-in simulated bus with the
reference sensor emulator on it (virtual time, exact stamps). Every other string is handed to
the real-link layer.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING
from urllib.parse import parse_qs, urlsplit

from .declaration import Declaration
from .links.base import Link
from .replay.link import is_replay

if TYPE_CHECKING:
    from .emulator.profile import Profile


class PortError(ValueError):
    """A port string the tool cannot use; the message says what to do instead."""


@dataclass
class SimSpec:
    faults: tuple[str, ...] = ()
    version: str = "14"
    address: str = "0"
    extra: dict[str, str] = field(default_factory=dict)


@dataclass
class OpenedPort:
    link: Link
    devices: list[object] = field(default_factory=list)
    declaration: Declaration | None = None  # what a simulated device declares about itself


def is_sim(port: str) -> bool:
    return port == "sim" or port.startswith("sim://") or port.startswith("sim:")


def parse_sim(port: str) -> SimSpec:
    """Parse ``sim://?faults=no-service-request,wrong-crc&version=1.3&address=5``."""
    query = urlsplit(port).query if "://" in port or "?" in port else ""
    params = {k: v[-1] for k, v in parse_qs(query, keep_blank_values=True).items()}
    spec = SimSpec()
    if "faults" in params:
        spec.faults = tuple(f.strip() for f in params.pop("faults").split(",") if f.strip())
    if "version" in params:
        given = params.pop("version").strip()
        if given not in ("1.3", "1.4"):
            raise PortError(f"sim version must be 1.3 or 1.4, not {given!r}")
        spec.version = given.replace(".", "")
    if "address" in params:
        spec.address = params.pop("address")
    for key in ("recorder-faults", "recorder"):  # recorder role: the recorder under test
        if key in params:
            spec.extra[key] = params.pop(key)
    if params:
        raise PortError(
            f"unknown sim parameters {sorted(params)} "
            "(known: faults, version, address, recorder-faults, recorder)"
        )
    return spec


def open_sim(spec: SimSpec) -> OpenedPort:
    """Build the simulated bus with one reference emulator on it."""
    from .emulator import FAULTS, default_profile, sim_sensor
    from .protocol.commands import ADDRESS_CHARS

    unknown = [f for f in spec.faults if f not in FAULTS]
    if unknown:
        raise PortError(
            f"unknown fault(s) {', '.join(unknown)}; `sdi12-conform faults` lists the known ones"
        )
    if len(spec.address) != 1 or spec.address not in ADDRESS_CHARS:
        raise PortError(f"sim address must be one of 0-9, A-Z, a-z, not {spec.address!r}")
    profile = replace(default_profile(spec.version), address=spec.address)
    _bus, link, emulator = sim_sensor(profile, faults=spec.faults)
    declared = emulator.faults.declared_profile(profile)  # the clean profile, not the faulted
    return OpenedPort(link, [emulator], sim_declaration(declared, spec))


def sim_declaration(profile: Profile, spec: SimSpec) -> Declaration:
    """What the simulated sensor's maker would declare: its clean profile (a fault is found
    on the wire, not handed to the tool in the declaration).

    Extended commands are opt-in on real devices; the simulated one declares its own, so the
    suite exercises them. The address is left to discovery (``?!``); a sensor asked for at
    address 0 is a unit fresh from the factory.
    """
    return Declaration(
        features={"address_change": bool(profile.address_settable)},
        extended=tuple(profile.extended),
        factory_fresh=spec.address == "0",
        source="built-in (the simulated sensor's profile)",
    )


def open_port(port: str, *, echo: str = "auto", direction: str = "none") -> OpenedPort:
    """Open ``port``; ``echo`` and ``direction`` describe a real bench (ignored on sim)."""
    if is_sim(port):
        return open_sim(parse_sim(port))
    if is_replay(port):
        return open_replay(port)
    if port.startswith("rfc2217-serve://"):
        raise PortError(
            f"port {port!r} serves played sensors to a recorder under test (--role recorder); "
            "to judge a sensor served over RFC 2217, connect to it with rfc2217://HOST:PORT"
        )
    if port.startswith(("exec:", "unix:")):  # a harness in another process, virtual time
        from .harness.channel import HarnessError
        from .harness.device import open_sensor_harness
        from .links.errors import PortUnavailable

        try:
            return OpenedPort(open_sensor_harness(port))
        except HarnessError as exc:
            raise PortUnavailable(str(exc)) from exc
    check_network_url(port)
    from .links.direction import DirectionLine
    from .links.echo import EchoMode
    from .links.factory import open_real_link

    try:
        bench = {"echo": EchoMode(echo), "direction": DirectionLine(direction)}
    except ValueError as exc:
        raise PortError(
            f"{exc}: --echo is auto, on or off; --direction is rts, dtr or none"
        ) from exc
    return OpenedPort(open_real_link(port, **bench))


def open_replay(port: str) -> OpenedPort:
    """``replay:PATH``: a saved sensor-role run's recorded sensor on the simulated bus."""
    from .replay.link import open_sensor_replay
    from .replay.recording import RecordingError

    try:
        link, recording = open_sensor_replay(port)
        return OpenedPort(link, declaration=recorded_declaration(recording.original_port))
    except RecordingError as exc:
        raise PortError(str(exc)) from exc


def recorded_declaration(port: str | None) -> Declaration | None:
    """What the recorded run's device declared when the tool built it (a simulated sensor
    declares its clean profile; a replay's, what its own recording's device declared)."""
    if port is None:
        return None
    if is_sim(port):
        return open_sim(parse_sim(port)).declaration
    if is_replay(port):
        from .replay.link import replay_path
        from .replay.recording import read_recording

        return recorded_declaration(read_recording(replay_path(port)).original_port)
    return None


def check_network_url(port: str) -> None:
    """``rfc2217://`` / ``socket://`` need HOST:PORT; pyserial's own complaint about a
    missing one is a TypeError from deep inside it."""
    scheme = port.split("://", 1)[0].lower() if "://" in port else ""
    if scheme not in ("rfc2217", "socket"):
        return
    parts = urlsplit(port)
    try:
        number = parts.port
    except ValueError:
        number = None
    if not parts.hostname or number is None:
        raise PortError(
            f"port {port!r}: write {scheme}://HOST:PORT, e.g. {scheme}://127.0.0.1:4001"
        )
