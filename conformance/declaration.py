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
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .preflight import address_problem

FEATURES = ("address_change", "continuous", "high_volume_ascii", "high_volume_binary")


class DeclarationError(ValueError):
    """The declaration file is unreadable or says something impossible (a usage error)."""


@dataclass(frozen=True)
class Declaration:
    address: str | None = None
    sdi12_version: str | None = None  # "13" / "14"
    features: dict[str, bool] = field(default_factory=dict)
    extended: tuple[str, ...] = ()
    measurements: dict[str, int] = field(default_factory=dict)
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


def load_declaration(path: str | Path) -> Declaration:
    try:
        raw = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DeclarationError(f"declaration file {path} does not exist") from None
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise DeclarationError(f"cannot read declaration {path}: {exc}") from None
    address = raw.get("address")
    if address is not None and address_problem(address):
        raise DeclarationError(f"{path}: address: {address_problem(address)}")
    version = raw.get("sdi12_version")
    features = raw.get("features", {})
    unknown = set(features) - set(FEATURES) - {"extended"}
    if unknown:
        raise DeclarationError(f"unknown features {sorted(unknown)}; known: {list(FEATURES)}")
    extended = features.get("extended", [])
    measurements = raw.get("measurements", {})
    if not all(isinstance(v, int) and 0 <= v <= 999 for v in measurements.values()):
        raise DeclarationError("measurement counts must be integers 0..999")
    return Declaration(
        address=address,
        sdi12_version=normalise_version(str(version)) if version is not None else None,
        features={k: bool(v) for k, v in features.items() if k in FEATURES},
        extended=tuple(str(e) for e in extended),
        measurements={str(k): int(v) for k, v in measurements.items()},
        factory_fresh=bool(raw.get("factory_fresh", False)),
        source=str(path),
    )
