"""The reference SDI-12 sensor emulator (sans-I/O), its profiles and its named faults."""

from .behaviour import Behaviour
from .faults import FAULTS, CompositionError, Fault, FaultSet, compose
from .profile import MeasurementSpec, Packet, Profile, default_profile
from .replies import Reply, ReplyKind
from .sensor import SensorEmulator
from .sim import sim_sensor

__all__ = [
    "FAULTS",
    "Behaviour",
    "CompositionError",
    "Fault",
    "FaultSet",
    "MeasurementSpec",
    "Packet",
    "Profile",
    "Reply",
    "ReplyKind",
    "SensorEmulator",
    "compose",
    "default_profile",
    "sim_sensor",
]
