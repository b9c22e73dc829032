"""The optional DUT declaration: what the manufacturer claims (TOML).

Without one the tool discovers what it can and says in the report what it assumed. Example::

    address = "0"
    sdi12_version = "1.4"        # or "1.3"
    factory_fresh = true         # never re-addressed: judge R-4.3-02 (address 0 as shipped)
    [features]
    address_change = true        # software-settable address (aAb!)
    continuous = true            # aR0!..aR9!
    high_volume_ascii = true     # aHA!
    high_volume_binary = true    # aHB!
    extended = ["XRST"]          # extended commands the suite may send (opt-in)
    [measurements]               # expected value counts per command code
    M = 3
    C = 20
    [ttt]                        # announced seconds per command code (sdi12-conform plan)
    M = 2
    C = 3

The recorder role (``--role recorder``) reads the same file: ``sdi12_version`` is what the
recorder claims, and a ``[recorder]`` table says what the logger can do (the sensor role
ignores that table, and the recorder role the sensor's keys)::

    sdi12_version = "1.3"
    [recorder]
    commands = ["?", "!", "I", "A", "M", "D", "MC", "V", "C", "CC", "R", "RC", "X", "IM"]
    crc = true                   # false: no aMC!/aCC!/aRCn! (whatever ``commands`` says)
    concurrent = true            # false: no aC!/aCn!/aCC!
    high_volume = false          # false: no aHA!/aHB!/aDBn!
    addresses = "0-9"            # the addresses it can poll: "0-9", "0-9,A-Z,a-z", "0-4"

See :mod:`conformance.recorder.capability` for what an absent capability does to a run.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from .protocol.commands import ADDRESS_CHARS
from .protocol.version import parse_version

ALLOWED_ADDRESSES = "0-9, A-Z, a-z"
FEATURES = ("address_change", "continuous", "high_volume_ascii", "high_volume_binary")


def address_problem(text: object) -> str | None:
    """Why ``text`` is not an SDI-12 address (one of 0-9, A-Z, a-z), or None if it is one.

    Here rather than with the other setting checks (:mod:`~conformance.preflight`) because a
    declaration is read far below them: the ports that open simulated sensors build one."""
    if isinstance(text, str) and len(text) == 1 and text in ADDRESS_CHARS:
        return None
    return f"{text!r} is not an SDI-12 address: use one character of {ALLOWED_ADDRESSES}"


class DeclarationError(ValueError):
    """The declaration file is unreadable or says something impossible (a usage error)."""


#: ``[recorder] commands`` tokens: the command kinds a logger can send (wire shape, no
#: address): ``?`` ?!, ``!`` a!, ``I`` aI!, ``A`` aAb!, ``M`` aM!/aMn!, ``D`` aDn!, ``MC``
#: aMC!/aMCn!, ``V`` aV!, ``C`` aC!/aCn!, ``CC`` aCC!/aCCn!, ``R`` aRn!, ``RC`` aRCn!, ``HA``
#: aHA!, ``HB`` aHB!, ``DB`` aDBn!, ``X`` extended commands, ``IM`` identify-measurement
#: and metadata commands (aIM!, aIM_001!...).
RECORDER_COMMANDS = (
    "?",
    "!",
    "I",
    "A",
    "M",
    "D",
    "MC",
    "V",
    "C",
    "CC",
    "R",
    "RC",
    "HA",
    "HB",
    "DB",
    "X",
    "IM",
)
RECORDER_KEYS: dict[str, type] = {
    "commands": list,
    "crc": bool,
    "concurrent": bool,
    "high_volume": bool,
    "addresses": str,
}


@dataclass(frozen=True)
class RecorderDeclaration:
    """What a data recorder's maker says it can do; None: not declared (assumed present)."""

    commands: frozenset[str] | None = None
    crc: bool | None = None
    concurrent: bool | None = None
    high_volume: bool | None = None
    addresses: frozenset[str] | None = None
    addresses_text: str = ""
    #: key -> "FILE:LINE", to cite the declaration in a finding
    where: dict[str, str] = field(default_factory=dict)


def parse_addresses(text: str) -> frozenset[str]:
    """``"0-9,A-Z"`` -> the address characters; ValueError says what is wrong."""
    chosen: set[str] = set()
    for part in (p.strip() for p in text.split(",")):
        if len(part) == 3 and part[1] == "-":
            lo, hi = part[0], part[2]
            if address_problem(lo) or address_problem(hi) or lo > hi:
                raise ValueError(f"{part!r} is not a range of addresses like 0-9 or A-Z")
            span = {c for c in ADDRESS_CHARS if lo <= c <= hi}
            if not ({lo, hi} <= span) or (lo.isdigit() != hi.isdigit()):
                raise ValueError(f"{part!r} mixes digits and letters: write 0-9,A-Z")
            chosen |= span
        elif address_problem(part) is None:
            chosen.add(part)
        else:
            raise ValueError(
                f'{part!r} is neither an address nor a range (e.g. "0-9", "0-9,A-Z,a-z")'
            )
    return frozenset(chosen)


@dataclass(frozen=True)
class Declaration:
    """What a maker declares about a sensor (address, version, features, extended commands,
    announced ttt): the run judges the device against this, and the plan times the run by it."""

    address: str | None = None
    sdi12_version: str | None = None  # "13" / "14"
    features: dict[str, bool] = field(default_factory=dict)
    extended: tuple[str, ...] = ()
    measurements: dict[str, int] = field(default_factory=dict)
    #: announced ttt (s) per measurement code: what ``sdi12-conform plan`` times the run by
    ttt: dict[str, int] = field(default_factory=dict)
    factory_fresh: bool = False  # the unit has not been re-addressed since it left the factory
    source: str = ""
    #: the ``[recorder]`` table (recorder role), None when the file has none
    recorder: RecorderDeclaration | None = None

    def feature(self, name: str) -> bool | None:
        """True/False when declared, None when the tool has to discover it."""
        return self.features.get(name)


def normalise_version(text: str) -> str:
    """``"1.4"``, ``"14"`` -> ``"14"``; raises DeclarationError for anything else."""
    digits = parse_version(text)
    if digits is None:
        raise DeclarationError(f"unsupported SDI-12 version {text!r} (use 1.3 or 1.4)")
    return digits


#: top-level keys and their TOML types; [features] and [measurements] are checked apart
TOP_LEVEL: dict[str, type | tuple[type, ...]] = {
    "address": str,
    "sdi12_version": (str, float),
    "factory_fresh": bool,
    "features": dict,
    "measurements": dict,
    "ttt": dict,
    "recorder": dict,
}
MEASUREMENT_CODE = re.compile(r"^(?:[MC]C?[1-9]?|H[AB]|V)$")


def load_declaration(path: str | Path) -> Declaration:
    """Read and check a declaration: an unknown key or a wrong type is refused with the
    file, the key and its line (a typo silently ignored would change what is judged)."""
    import tomllib  # here: a run without a declaration (every sim run) never parses TOML

    try:
        text = Path(path).read_text(encoding="utf-8")
        raw = tomllib.loads(text)
    except FileNotFoundError:
        raise DeclarationError(f"declaration file {path} does not exist") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise DeclarationError(f"cannot read declaration {path}: {exc}") from None

    def refuse(table: str | None, key: str, problem: str) -> DeclarationError:
        where = f"[{table}] {key}" if table else key
        return DeclarationError(f"{path}:{_line_of(text, table, key)}: {where}: {problem}")

    for key, value in raw.items():
        if key not in TOP_LEVEL:
            known = ", ".join(TOP_LEVEL)
            raise refuse(None, key, f"unknown key (known: {known})")
        if not isinstance(value, TOP_LEVEL[key]):
            raise refuse(None, key, f"must be a {_type_name(TOP_LEVEL[key])}, not {value!r}")
    address = raw.get("address")
    if address is not None and address_problem(address):
        raise refuse(None, "address", address_problem(address) or "")
    version = raw.get("sdi12_version")
    try:
        claimed = normalise_version(str(version)) if version is not None else None
    except DeclarationError as exc:
        raise refuse(None, "sdi12_version", str(exc)) from None
    features = raw.get("features", {})
    for key, value in features.items():
        if key == "extended":
            if not (isinstance(value, list) and all(isinstance(e, str) for e in value)):
                raise refuse("features", key, 'must be a list of strings, e.g. ["XSN"]')
        elif key not in FEATURES:
            known = ", ".join((*FEATURES, "extended"))
            raise refuse("features", key, f"unknown feature (known: {known})")
        elif not isinstance(value, bool):
            raise refuse("features", key, f"must be true or false, not {value!r}")
    measurements = raw.get("measurements", {})
    for key, value in measurements.items():
        if not MEASUREMENT_CODE.match(key):
            raise refuse("measurements", key, "not a measurement command (M, M1..M9, C, MC1...)")
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 999:
            raise refuse("measurements", key, f"must be a value count 0..999, not {value!r}")
    ttt = raw.get("ttt", {})
    for key, value in ttt.items():
        if not MEASUREMENT_CODE.match(key):
            raise refuse("ttt", key, "not a measurement command (M, M1..M9, C, MC1...)")
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 999:
            raise refuse("ttt", key, f"must be whole seconds 0..999, not {value!r}")
    recorder = None
    if "recorder" in raw:
        recorder = _recorder_table(
            raw["recorder"], refuse, lambda key: _line_of(text, "recorder", key), path
        )
    return Declaration(
        address=address,
        sdi12_version=claimed,
        features={k: v for k, v in features.items() if k in FEATURES},
        extended=tuple(features.get("extended", [])),
        measurements=dict(measurements),
        ttt=dict(ttt),
        factory_fresh=raw.get("factory_fresh", False),
        source=str(path),
        recorder=recorder,
    )


def _recorder_table(table: dict, refuse, line_of, path: str | Path) -> RecorderDeclaration:  # noqa: ANN001
    """Check ``[recorder]`` as strictly as the rest: unknown key, wrong type, unknown token."""
    for key, value in table.items():
        if key not in RECORDER_KEYS:
            raise refuse("recorder", key, f"unknown key (known: {', '.join(RECORDER_KEYS)})")
        kind = RECORDER_KEYS[key]
        if not isinstance(value, kind):
            raise refuse("recorder", key, f"must be a {_type_name(kind)}, not {value!r}")
    commands = table.get("commands")
    if commands is not None:
        unknown = [c for c in commands if c not in RECORDER_COMMANDS]
        if unknown or not all(isinstance(c, str) for c in commands):
            raise refuse(
                "recorder",
                "commands",
                f"unknown command kind(s) {unknown!r} (known: {' '.join(RECORDER_COMMANDS)})",
            )
    families = {"crc": ("MC", "CC", "RC"), "concurrent": ("C", "CC"), "high_volume": ("HA", "HB")}
    for key, tokens in families.items():
        listed = [t for t in tokens if commands is not None and t in commands]
        if table.get(key) is False and listed:
            raise refuse(
                "recorder", key, f"false, but [recorder] commands lists {' '.join(listed)}"
            )
    addresses = None
    if "addresses" in table:
        try:
            addresses = parse_addresses(table["addresses"])
        except ValueError as exc:
            raise refuse("recorder", "addresses", str(exc)) from None
    return RecorderDeclaration(
        commands=frozenset(commands) if commands is not None else None,
        crc=table.get("crc"),
        concurrent=table.get("concurrent"),
        high_volume=table.get("high_volume"),
        addresses=addresses,
        addresses_text=table.get("addresses", ""),
        where={key: f"{path}:{line_of(key)}" for key in table},
    )


def _type_name(kind: type | tuple[type, ...]) -> str:
    names = {
        str: "string",
        float: "number",
        bool: "true/false",
        dict: "table",
        int: "integer",
        list: "list",
    }
    kinds = kind if isinstance(kind, tuple) else (kind,)
    return " or ".join(names.get(k, k.__name__) for k in kinds)


def _line_of(text: str, table: str | None, key: str) -> int | str:
    """The line that sets ``key`` in ``[table]`` (top level when None); '?' if not found."""
    current = None
    pattern = re.compile(rf"^\s*(?:\"{re.escape(key)}\"|{re.escape(key)})\s*=")
    for number, line in enumerate(text.splitlines(), start=1):
        header = re.match(r"^\s*\[([^\]]+)\]", line)
        if header:
            current = header.group(1).strip()
            if current == key and table is None:
                return number
            continue
        if current == table and pattern.match(line):
            return number
    return "?"
