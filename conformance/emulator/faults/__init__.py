"""Named, composable deviations of the reference sensor (the suite's fault-detection matrix).

A :class:`Fault` changes the emulator through up to three hooks:

- ``settings``: overrides of :class:`~conformance.emulator.behaviour.Behaviour` (timing
  numbers and behaviour switches);
- ``rewrite``: a transform of each :class:`~conformance.emulator.replies.Reply` before it is
  encoded (return None to suppress the reply);
- ``profile``: a transform of the :class:`~conformance.emulator.profile.Profile` (values,
  counts, metadata), so that value-level faults still go through the normal packing.

``violates`` lists the requirement IDs the fault breaks, and only those: for every fault the
suite run against the faulty emulator must FAIL (or WARN, for SHOULD rules and lenient
decisions such as A18) exactly these IDs. Conventions used when choosing them:

- Where the catalogue has a rule for the specific reply type, a fault declares that rule and
  not the general one that also covers it: HA data over 75 characters is R-5.1-03 (not also
  R-4.4-05), R data over 75 is R-4.4.8.1-01, a D reply without CR LF is R-4.2-03 (not also
  the D format rule R-4.4.8-01), a metadata record without units is R-6.2.2-01.
- R-4.4-01 ("a well-formed answer to every basic command") is declared, next to the specific
  rule, only where a basic command gets no answer at all.
- Rewrites of ``atttn`` replies apply to the identify form too, so R-6.1-02 (identify reply
  equals the command's reply) stays intact unless the fault is about that rule.
- A fault applies to the default v1.4 profile unless ``version`` says otherwise.

Faults compose: :func:`compose` merges their settings, chains their rewrites and applies
their profile transforms. A set is refused (:class:`CompositionError`) where two faults set
one knob to different values or one declares that it ``masks`` the other; otherwise the
result does not depend on the order and each member's deviation still shows on the wire
(tests/emulator/test_fault_composition.py checks every pair whose hooks touch the same thing).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace
from types import MappingProxyType
from typing import Any

from ..behaviour import Behaviour
from . import (
    addressing,
    bus,
    firmware_replies,
    high_volume,
    measurements,
    metadata,
    replies,
    timing,
)
from .model import CompositionError, Fault, FaultSet, ProfileTransform, Rewrite, clash

__all__ = [
    "FAULTS",
    "CompositionError",
    "Fault",
    "FaultSet",
    "ProfileTransform",
    "Rewrite",
    "clash",
    "compose",
    "conflicts",
]

#: The registry in the order its faults were added, which is the order the matrix, the
#: reports and ``sdi12-conform faults`` list them in: each family module holds its faults in
#: runs, one per stage of the suite's history that touched the family.
_RUNS: tuple[tuple[Fault, ...], ...] = (
    # identification and reply format
    replies.FORMAT,
    # CRC
    replies.CRC,
    # service requests
    measurements.SERVICE_REQUESTS,
    # aborts
    measurements.ABORTS,
    # data buffer
    measurements.DATA_BUFFER,
    # addressing
    addressing.ADDRESSING,
    # counts
    measurements.COUNTS,
    # metadata
    metadata.METADATA,
    # high-volume binary
    high_volume.BINARY,
    # timing
    timing.TIMING,
    # faults that complete the sensor-role coverage
    measurements.COVERAGE_DATA,
    timing.COVERAGE_BAUD,
    addressing.COVERAGE,
    measurements.COVERAGE,
    replies.COVERAGE,
    high_volume.COVERAGE,
    metadata.COVERAGE,
    timing.COVERAGE_GAP,
    # deviations found on a third-party sensor (issue 10)
    replies.THIRD_PARTY,
    measurements.THIRD_PARTY_GROUPS,
    metadata.THIRD_PARTY_COUNT,
    measurements.THIRD_PARTY_BUFFER,
    metadata.THIRD_PARTY_CRC,
    # timing just inside the limits (boundary probes, issue 10)
    timing.BOUNDARIES,
    # version specific
    measurements.VERSION_13,
    # what real firmware answers where the reference is silent (issue 18)
    firmware_replies.FIRMWARE_REPLIES,
    # what only a bus of several sensors shows (issue 23, item 2)
    bus.BUS,
    # a break from the sensor before its reply (docs/kit.md, twenty-fifth round)
    timing.SENSOR_BREAK,
)


def _registry() -> dict[str, Fault]:
    registry: dict[str, Fault] = {}
    for run in _RUNS:
        for fault in run:
            if fault.name in registry:
                raise ValueError(f"duplicate fault {fault.name}")
            registry[fault.name] = fault
    return registry


#: Every fault by name.
FAULTS: Mapping[str, Fault] = MappingProxyType(_registry())


def conflicts(names: Iterable[str]) -> list[str]:
    """Why the named faults cannot be composed (one line per clashing pair; empty if they
    can). KeyError naming an unknown fault."""
    chosen = []
    for name in names:
        if name not in FAULTS:
            raise KeyError(f"unknown fault {name!r}")
        chosen.append(FAULTS[name])
    reasons = []
    for i, first in enumerate(chosen):
        for second in chosen[i + 1 :]:
            reason = clash(first, second)
            if reason is not None:
                reasons.append(reason)
    return reasons


def compose(names: Iterable[str]) -> FaultSet:
    """The :class:`FaultSet` for fault names (KeyError naming the unknown fault,
    :class:`CompositionError` naming a pair that cannot be composed)."""
    names = tuple(dict.fromkeys(names))
    reasons = conflicts(names)
    if reasons:
        raise CompositionError("; ".join(reasons))
    chosen = tuple(FAULTS[name] for name in names)
    settings: dict[str, Any] = {}
    for fault in chosen:
        settings.update(fault.settings)
    return FaultSet(chosen, replace(Behaviour(), **settings))
