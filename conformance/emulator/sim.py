"""One emulated sensor on an in-process bus: the quickest way to a working SDI-12 line."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from ..sim.bus import SimBus, SimLink
from .profile import Profile, default_profile
from .sensor import SensorEmulator


def sim_sensor(
    profile: Profile | None = None,
    faults: Sequence[str] = (),
    quirks: Mapping[str, Any] | None = None,
) -> tuple[SimBus, SimLink, SensorEmulator]:
    """A :class:`SimBus` with one :class:`SensorEmulator` (default v1.4 profile) attached,
    and the tool's :class:`SimLink` to it (``quirks``: a firmware profile's legal settings).
    Used by tests and by ``--port sim``."""
    chosen = profile if profile is not None else default_profile()
    emulator = SensorEmulator(chosen, faults, quirks=quirks)
    bus = SimBus([emulator])
    return bus, SimLink(bus), emulator
