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
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .protocol.commands import ADDRESS_CHARS

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


@dataclass(frozen=True)
class Declaration:
    address: str | None = None
    sdi12_version: str | None = None  # "13" / "14"
    features: dict[str, bool] = field(default_factory=dict)
    extended: tuple[str, ...] = ()
    measurements: dict[str, int] = field(default_factory=dict)
    #: announced ttt (s) per measurement code: what ``sdi12-conform plan`` times the run by
    ttt: dict[str, int] = field(default_factory=dict)
    factory_fresh: bool = False  # the unit has not been re-addressed since it left the factory
    source: str = ""

    def feature(self, name: str) -> bool | None:
        """True/False when declared, None when the tool has to discover it."""
        return self.features.get(name)


def normalise_version(text: str) -> str:
    """``"1.4"``, ``"14"`` -> ``"14"``; raises DeclarationError for anything else."""
    digits = text.replace(".", "").strip()
    if digits not in ("13", "14"):
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
}
MEASUREMENT_CODE = re.compile(r"^(?:[MC]C?[1-9]?|H[AB]|V)$")


def load_declaration(path: str | Path) -> Declaration:
    """Read and check a declaration: an unknown key or a wrong type is refused with the
    file, the key and its line (a typo silently ignored would change what is judged)."""
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
    return Declaration(
        address=address,
        sdi12_version=claimed,
        features={k: v for k, v in features.items() if k in FEATURES},
        extended=tuple(features.get("extended", [])),
        measurements=dict(measurements),
        ttt=dict(ttt),
        factory_fresh=raw.get("factory_fresh", False),
        source=str(path),
    )


def _type_name(kind: type | tuple[type, ...]) -> str:
    names = {str: "string", float: "number", bool: "true/false", dict: "table", int: "integer"}
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
