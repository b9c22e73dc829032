"""The fault model: what one deviation of the reference sensor is, and several together.

A :class:`Fault` changes the emulator through up to three hooks (``settings`` overriding
:class:`~conformance.emulator.behaviour.Behaviour`, a ``rewrite`` of each reply, a ``profile``
transform) and names the requirements it breaks; a :class:`FaultSet` applies several in order.
The registry of named faults is :mod:`conformance.emulator.faults`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Any

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
    version: str = "14"
    #: Requirements the fault honestly leaves undecided (the description says why); the
    #: matrix demands exactly these INCONCLUSIVE, so collateral is declared, never ignored.
    inconclusive: tuple[str, ...] = ()
    #: What the maker's declaration says where it differs from the clean profile (say, the
    #: names of its extended commands). On ``sim`` the declaration is the clean profile's:
    #: a fault is caught from the wire, never from names the tool was handed by the fault.
    declares: ProfileTransform | None = None

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
        object.__setattr__(self, "settings", MappingProxyType(dict(self.settings)))


@dataclass(frozen=True)
class FaultSet:
    """Several faults applied together."""

    faults: tuple[Fault, ...] = ()
    behaviour: Behaviour = field(default_factory=Behaviour)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.faults)

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

    def declared_profile(self, clean: Profile) -> Profile:
        """The profile the maker's declaration describes: the clean one, changed only by
        what a fault says its maker declares."""
        for fault in self.faults:
            if fault.declares is not None:
                clean = fault.declares(clean)
        return clean
