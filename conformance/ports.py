"""Turn a ``--port`` string into a link: every kind of link, looked up in one registry.

Each kind registers itself with :mod:`~conformance.links.registry` when its module is
imported; this module has the built-in ones imported when a port first needs them
(:func:`builtin_kinds`, deferred: a ``--port sim`` run loads none of them) and registers
the three it holds itself, sole kinds whose port strings no other kind claims: ``sim`` /
``sim://?faults=a,b&version=1.3&address=0``, the built-in simulated bus with the reference
sensor emulator on it (virtual time, exact stamps); ``replay:PATH``, a saved run's recorded
sensor played back on that bus; and ``rfc2217-serve://``, which has no sensor-role opener
(it serves played sensors to a recorder under test). A new kind of link is a module that
registers its :class:`LinkKind`, plus its import in :func:`builtin_kinds`; its recorder-role
opener, if it has one, goes in :mod:`conformance.recorder.openers`.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field, replace
from urllib.parse import parse_qs, urlsplit

from .declaration import Declaration, DeclarationError, load_declaration
from .emulator import FAULTS, CompositionError, Profile, compose, default_profile, sim_sensor
from .emulator.declared import declared_profile
from .emulator.profiles import PROFILES, profile_settings
from .emulator.sensor import SensorEmulator
from .links.base import LinkInfo
from .links.errors import PortError
from .links.registry import LinkKind, OpenedPort, PortOptions, defer, find, register
from .protocol.commands import ADDRESS_CHARS
from .protocol.version import V14, format_version, parse_version
from .replay.link import is_replay

__all__ = ["OpenedPort", "PortError", "SimSpec", "is_sim", "open_port", "open_sim", "parse_sim"]


def builtin_kinds() -> tuple[object, ...]:
    """The modules whose kinds of link register themselves on import (besides the three
    below), imported when a port string is looked up that no sole kind claims, or when the
    table of kinds is read (:func:`conformance.links.registry.defer`)."""
    from .harness import device as harness_device
    from .links import adapter_link, factory
    from .replay import recording_link

    return (factory, adapter_link, harness_device, recording_link)


defer(builtin_kinds)


@dataclass
class SimSpec:
    """A ``sim://`` port string read apart: the simulated sensor's faults, profiles, version,
    address, declaration, or the sensors of a simulated bus."""

    faults: tuple[str, ...] = ()
    profiles: tuple[str, ...] = ()  # firmware profiles (conformance.emulator.profiles)
    version: str = V14
    address: str = "0"
    extra: dict[str, str] = field(default_factory=dict)
    #: a declaration file: the simulated sensor plays what it declares (sdi12-conform plan)
    declaration: str = ""
    #: a bus of several emulators (``sensors=0,1:wrong-crc+no-crc,3``): each one's address and
    #: own faults (``faults=`` applies to all of them); empty: the one sensor at ``address``
    sensors: tuple[tuple[str, tuple[str, ...]], ...] = ()


def parse_sensors(text: str) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """``0,1:wrong-crc+no-crc,3`` -> (('0', ()), ('1', ('wrong-crc', 'no-crc')), ('3', ())).
    An address may appear twice (a duplicate address is a bus fault the run must find);
    each address and fault is checked where the profile is made (:func:`sim_profile`)."""
    sensors = []
    for item in (part.strip() for part in text.split(",")):
        address, _, faults = item.partition(":")
        if not address:
            raise PortError(f"sim sensors: an empty entry in {text!r} (use sensors=0,1:FAULT,3)")
        # a query string reads '+' as a space: either separates one sensor's faults
        sensors.append((address, tuple(faults.replace("+", " ").split())))
    if len(sensors) < 2:
        raise PortError(f"sim sensors= puts several sensors on the bus, not {len(sensors)}")
    return tuple(sensors)


def is_sim(port: str) -> bool:
    return port == "sim" or port.startswith("sim://") or port.startswith("sim:")


def parse_sim(port: str) -> SimSpec:
    """Parse ``sim://?faults=no-service-request,wrong-crc&version=1.3&address=5``."""
    query = urlsplit(port).query if "://" in port or "?" in port else ""
    params = {k: v[-1] for k, v in parse_qs(query, keep_blank_values=True).items()}
    spec = SimSpec()
    if "faults" in params:
        spec.faults = tuple(f.strip() for f in params.pop("faults").split(",") if f.strip())
    if "profile" in params:
        spec.profiles = tuple(p.strip() for p in params.pop("profile").split(",") if p.strip())
    if "version" in params:
        given = params.pop("version").strip()
        digits = parse_version(given)
        if digits is None or given != format_version(digits):  # dotted only: 1.3 or 1.4
            raise PortError(f"sim version must be 1.3 or 1.4, not {given!r}")
        spec.version = digits
    if "address" in params:
        spec.address = params.pop("address")
    if "sensors" in params:
        if "address" in query or "declaration" in params:
            raise PortError(
                "sim sensors= gives every sensor its address: no address= or declaration="
            )
        spec.sensors = parse_sensors(params.pop("sensors"))
    if "declaration" in params:
        spec.declaration = params.pop("declaration")
        declared = _load(spec.declaration)
        if "version" not in query and declared.sdi12_version:
            spec.version = declared.sdi12_version
        if "address" not in query and declared.address:
            spec.address = declared.address
    for key in ("recorder-faults", "recorder"):  # recorder role: the recorder under test
        if key in params:
            spec.extra[key] = params.pop(key)
    if params:
        known = ("faults", "profile", "version", "address", "sensors", "declaration")
        known += ("recorder-faults", "recorder")
        near = [m for p in sorted(params) for m in difflib.get_close_matches(p, known, 1)]
        raise PortError(
            f"unknown sim parameter(s) {', '.join(sorted(params))}"
            + (f" (did you mean {', '.join(near)}?)" if near else "")
            + f"; known: {', '.join(known)}"
        )
    return spec


def sim_profile(spec: SimSpec) -> Profile:
    """The reference emulator's profile a sim URL asks for, its faults and address checked
    (:class:`PortError` with the reason): the one check ``sim`` and ``emulate`` share."""
    unknown_profiles = [p for p in spec.profiles if p not in PROFILES]
    if unknown_profiles:
        from .suggest import did_you_mean  # difflib: only for a mistyped name

        raise PortError(
            f"unknown profile(s) {', '.join(unknown_profiles)}"
            f"{did_you_mean(unknown_profiles, PROFILES)}; "
            "`sdi12-conform faults` lists the known ones"
        )
    unknown = [f for f in spec.faults if f not in FAULTS]
    if unknown:
        from .suggest import did_you_mean

        raise PortError(
            f"unknown fault(s) {', '.join(unknown)}{did_you_mean(unknown, FAULTS)}; "
            "`sdi12-conform faults` lists the known ones"
        )
    if len(spec.address) != 1 or spec.address not in ADDRESS_CHARS:
        raise PortError(f"sim address must be one of 0-9, A-Z, a-z, not {spec.address!r}")
    if spec.declaration:
        profile = declared_profile(_load(spec.declaration), spec.version)
        profile = replace(profile, address=spec.address)
    else:
        profile = replace(default_profile(spec.version), address=spec.address)
    try:
        misfits = compose(all_faults(spec)).misfits(profile)
    except CompositionError as exc:
        raise PortError(f"sim faults cannot be combined: {exc}") from None
    if misfits:
        raise PortError("; ".join(misfits))
    return profile


def all_faults(spec: SimSpec) -> tuple[str, ...]:
    """The faults of the URL's firmware profiles, then its own ``faults=``."""
    return (*profile_settings(spec.profiles)[0], *spec.faults)


def open_sim(spec: SimSpec) -> OpenedPort:
    """Build the simulated bus with one reference emulator on it (several: ``sensors=``)."""
    if spec.sensors:
        return open_sim_bus(spec)
    profile = sim_profile(spec)
    quirks = profile_settings(spec.profiles)[1]
    _bus, link, emulator = sim_sensor(profile, faults=all_faults(spec), quirks=quirks)
    if spec.declaration:  # it plays a maker's declaration: the run is judged by that one
        return OpenedPort(link, [emulator], _load(spec.declaration))
    declared = emulator.faults.declared_profile(profile)  # the clean profile, not the faulted
    return OpenedPort(link, [emulator], sim_declaration(declared, spec))


def open_sim_bus(spec: SimSpec) -> OpenedPort:
    """Several reference emulators on one simulated bus, each with its address, its serial
    number (``SN0001``, ``SN0002``... in the order given, so that two sensors at one address
    give different ``aI!`` replies and collide, as two real ones would) and its faults.
    Every character they send is stamped ``dut``, as a real bus shows it: which sensor spoke
    is for the run to tell from the address, not for the simulation to give away."""
    from .sim.bus import SimBus, SimLink

    emulators = bus_emulators(spec)
    link = SimLink(SimBus(list(emulators)))
    declared = emulators[0].faults.declared_profile(default_profile(spec.version))
    bus_spec = replace(spec, address="")  # no sensor of a bus is called fresh from the factory
    return OpenedPort(link, list(emulators), sim_declaration(declared, bus_spec))


def bus_emulators(spec: SimSpec) -> list[SensorEmulator]:
    """The emulators of ``sensors=`` (see :func:`open_sim_bus`), each checked as one sim URL
    would be (:class:`PortError` with the reason): the one place the simulated bus and
    ``emulate --sensors`` (a bus served in real time) make them, so both carry the same serial
    numbers and faults."""
    from .transcript import DUT

    emulators = []
    for n, (address, own) in enumerate(spec.sensors, start=1):
        one = replace(spec, address=address, faults=(*spec.faults, *own), sensors=())
        profile = replace(sim_profile(one), optional=f"SN{n:04d}")
        quirks = profile_settings(spec.profiles)[1]
        emulators.append(SensorEmulator(profile, all_faults(one), name=DUT, quirks=quirks))
    return emulators


def _load(path: str) -> Declaration:
    try:
        return load_declaration(path)
    except DeclarationError as exc:
        raise PortError(f"sim declaration: {exc}") from None


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


def open_port(
    port: str,
    *,
    echo: str = "auto",
    direction: str = "none",
    timing_uncertainty: float | None = None,
) -> OpenedPort:
    """Open ``port`` for the sensor role; ``echo`` and ``direction`` describe a real bench
    (kinds in virtual time ignore them). ``timing_uncertainty`` (s, the user's) is applied
    here, to whatever kind of link opened: it widens the link's own figure, never narrows."""
    kind = find(port)
    if kind.open_sensor_role is None:
        raise PortError(f"port {port!r} cannot judge a sensor: {kind.wrong_role}")
    opened = kind.open_sensor_role(port, PortOptions(echo, direction, timing_uncertainty))
    opened.link.widen(timing_uncertainty)
    return opened


def _open_sim(port: str, options: PortOptions) -> OpenedPort:
    spec = parse_sim(port)
    other = sorted(set(spec.extra) & {"recorder-faults", "recorder"})
    if other:
        raise PortError(
            f"sim://?{other[0]}= belongs to the recorder role (--role recorder); "
            "for a faulty simulated sensor use sim://?faults=NAME"
        )
    return open_sim(spec)


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


SIM = register(
    LinkKind(
        "sim",
        matches=is_sim,
        open_sensor_role=_open_sim,
        info=LinkInfo(kind="sim", virtual_time=True),
        example="sim://?faults=no-service-request&version=1.3",
        sole=True,
    )
)
REPLAY = register(
    LinkKind(
        "replay",
        matches=is_replay,
        open_sensor_role=lambda port, options: open_replay(port),
        info=LinkInfo(kind="replay", virtual_time=True),
        example="replay:reports/20250101-120000-sensor",
        sole=True,
    )
)
SERVED = register(
    LinkKind(
        "rfc2217-serve",
        matches=lambda port: port.startswith("rfc2217-serve://"),
        open_sensor_role=None,
        info=LinkInfo(kind="rfc2217-serve"),
        example="rfc2217-serve://127.0.0.1:0",
        wrong_role=(
            "it serves played sensors to a recorder under test (--role recorder); to judge a "
            "sensor served over RFC 2217, connect to it with rfc2217://HOST:PORT"
        ),
        sole=True,
    )
)
