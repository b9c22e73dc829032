"""One emulated sensor on an in-process bus: the quickest way to a working SDI-12 line."""

from __future__ import annotations

from collections.abc import Sequence

from ..sim.bus import SimBus, SimLink
from .profile import Profile, default_profile
from .sensor import SensorEmulator


def sim_sensor(
    profile: Profile | None = None, faults: Sequence[str] = ()
) -> tuple[SimBus, SimLink, SensorEmulator]:
    """A :class:`SimBus` with one :class:`SensorEmulator` (default v1.4 profile) attached,
    and the tool's :class:`SimLink` to it. Used by tests and by ``--port sim``."""
    emulator = SensorEmulator(profile if profile is not None else default_profile(), faults)
    bus = SimBus([emulator])
    return bus, SimLink(bus), emulator
