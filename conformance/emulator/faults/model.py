"""The fault model: what one deviation of the reference sensor is, and several together.

A :class:`Fault` changes the emulator through up to three hooks (``settings`` overriding
:class:`~conformance.emulator.behaviour.Behaviour`, a ``rewrite`` of each reply, a ``profile``
transform) and names the requirements it breaks; a :class:`FaultSet` applies several together.
The registry of named faults is :mod:`conformance.emulator.faults`.

Two faults compose when each one's deviation still shows on the wire beside the other's:
their settings must not clash (one knob, two values) and neither may remove what the other
deviates in. Where one does, that is data on the fault (``masks``, with the reason), and
:func:`clash` names the conflict so that ``compose`` refuses the set instead of letting one
fault silently undo the other.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Any

from ...protocol.version import V14, format_version
from ..behaviour import Behaviour
from ..profile import Profile
from ..replies import Reply

Rewrite = Callable[[Reply], Reply | None]
ProfileTransform = Callable[[Profile], Profile]

_BEHAVIOUR_FIELDS = frozenset(f.name for f in fields(Behaviour))


@dataclass(frozen=True)
class Fault:
    """One deviation: what it does, which requirements it breaks, and how."""

    name: str
    description: str
    violates: tuple[str, ...]
    settings: Mapping[str, Any] = field(default_factory=dict)
    rewrite: Rewrite | None = None
    profile: ProfileTransform | None = None
    version: str = V14
    #: Requirements the fault honestly leaves undecided (the description says why); the
    #: matrix demands exactly these INCONCLUSIVE, so collateral is declared, never ignored.
    inconclusive: tuple[str, ...] = ()
    #: What the maker's declaration says where it differs from the clean profile (say, the
    #: names of its extended commands). On ``sim`` the declaration is the clean profile's:
    #: a fault is caught from the wire, never from names the tool was handed by the fault.
    declares: ProfileTransform | None = None
    #: Faults this one removes the deviation of, each with the reason (say, a measurement
    #: without values hides a malformed value): the two together are refused by ``compose``.
    masks: Mapping[str, str] = field(default_factory=dict)
    #: What of the sensor the fault deviates in, when that is not in every version's profile:
    #: measurement keys (``HB``), extended command names (``XHELP``), or ``v1.4`` for the
    #: commands only v1.4 has (identify measurement, metadata). A sensor without it cannot
    #: show the fault, so a sim URL asking for both is refused (:meth:`FaultSet.misfits`).
    needs: tuple[str, ...] = ()
    #: The one thing the fault replaces, when another fault may replace it too (say, "the
    #: first value of aM!"): two faults replacing the same thing cannot both show.
    replaces: str | None = None
    #: The fault shows only beside other sensors on one bus (``sim://?sensors=``): the
    #: single-sensor matrix leaves it to the bus cases' own matrix.
    bus: bool = False

    def __post_init__(self) -> None:
        if not self.violates:
            raise ValueError(f"fault {self.name} declares no requirement")
        if set(self.violates) & set(self.inconclusive):
            raise ValueError(f"fault {self.name}: a requirement cannot be broken and undecided")
        unknown = set(self.settings) - _BEHAVIOUR_FIELDS
        if unknown:
            raise ValueError(f"fault {self.name}: unknown settings {sorted(unknown)}")
        if not (self.settings or self.rewrite or self.profile):
            raise ValueError(f"fault {self.name} changes nothing")
        if self.name in self.masks:
            raise ValueError(f"fault {self.name} cannot mask itself")
        object.__setattr__(self, "settings", MappingProxyType(dict(self.settings)))
        object.__setattr__(self, "masks", MappingProxyType(dict(self.masks)))


class CompositionError(ValueError):
    """Faults that cannot be composed: one would undo or hide another."""


def clash(first: Fault, second: Fault) -> str | None:
    """Why ``first`` and ``second`` cannot be composed, or None when each still shows its
    deviation beside the other (in either order)."""
    for name, value in first.settings.items():
        if name in second.settings and second.settings[name] != value:
            return (
                f"{first.name} and {second.name} both set {name} "
                f"({value!r} and {second.settings[name]!r}): only one could show"
            )
    if first.replaces is not None and first.replaces == second.replaces:
        return f"{first.name} and {second.name} both replace {first.replaces}"
    for one, other in ((first, second), (second, first)):
        if other.name in one.masks:
            return f"{one.name} masks {other.name}: {one.masks[other.name]}"
    return None


def _has(profile: Profile, feature: str) -> bool:
    if feature == "v1.4":
        return profile.v14
    return feature in profile.measurements or feature in profile.extended


@dataclass(frozen=True)
class FaultSet:
    """Several faults applied together."""

    faults: tuple[Fault, ...] = ()
    behaviour: Behaviour = field(default_factory=Behaviour)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.faults)

    @property
    def behaviour_settings(self) -> dict[str, Any]:
        """The settings the faults override (the rest of :attr:`behaviour` is the default)."""
        merged: dict[str, Any] = {}
        for fault in self.faults:
            merged.update(fault.settings)
        return merged

    @property
    def violates(self) -> tuple[str, ...]:
        seen: dict[str, None] = {}
        for fault in self.faults:
            seen.update(dict.fromkeys(fault.violates))
        return tuple(seen)

    def rewrite(self, reply: Reply) -> Reply | None:
        current: Reply | None = reply
        for fault in self.faults:
            if current is None:
                return None
            if fault.rewrite is not None:
                current = fault.rewrite(current)
        return current

    def apply_profile(self, profile: Profile) -> Profile:
        for fault in self.faults:
            if fault.profile is not None:
                profile = fault.profile(profile)
        return profile

    def misfits(self, profile: Profile) -> list[str]:
        """Why a sensor with ``profile`` cannot show some of the faults (one line each): a
        feature a fault needs is missing (``needs``), or its profile edit finds nothing to
        edit (a key the profile lacks)."""
        reasons = []
        for fault in self.faults:
            missing = [f for f in fault.needs if not _has(profile, f)]
            if not missing and fault.profile is not None:
                try:
                    fault.profile(profile)
                except KeyError as exc:
                    missing = [str(exc.args[0])]
            if missing:
                reasons.append(
                    f"fault {fault.name} needs {', '.join(missing)}, which a "
                    f"v{format_version(profile.version)} sensor does not have"
                )
        return reasons

    def declared_profile(self, clean: Profile) -> Profile:
        """The profile the maker's declaration describes: the clean one, changed only by
        what a fault says its maker declares."""
        for fault in self.faults:
            if fault.declares is not None:
                clean = fault.declares(clean)
        return clean
