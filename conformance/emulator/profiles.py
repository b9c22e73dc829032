"""Multi-deviation profiles: what real sensor firmware does, as named sets of emulator faults.

A single fault proves that the suite catches one deviation; real firmware has several at
once (issue 18: four public implementations tried behind ``exec:``). Each profile is data: a
name for ``sim://?profile=NAME``, a description of the firmware class it models, the faults
(by registry name) and ``quirks``, legal but unusual behaviour settings (say, a reply delay
near the limit) that the suite must not mistake for a deviation. ``profile=`` combines with
``faults=``; the faults of both are composed by :func:`~conformance.emulator.faults.compose`,
so a profile never hides a clash.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Any

from .behaviour import Behaviour
from .faults import FAULTS, compose

_BEHAVIOUR_FIELDS = frozenset(f.name for f in fields(Behaviour))


@dataclass(frozen=True)
class FirmwareProfile:
    """One class of real firmware: its faults and its legal quirks."""

    name: str
    description: str
    faults: tuple[str, ...] = ()
    quirks: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = [f for f in self.faults if f not in FAULTS]
        if unknown:
            raise ValueError(f"profile {self.name}: unknown faults {unknown}")
        if set(self.quirks) - _BEHAVIOUR_FIELDS:
            raise ValueError(f"profile {self.name}: unknown quirks {sorted(self.quirks)}")
        if not (self.faults or self.quirks):
            raise ValueError(f"profile {self.name} changes nothing")
        compose(self.faults)  # CompositionError: a profile's own faults must compose
        object.__setattr__(self, "quirks", MappingProxyType(dict(self.quirks)))


PROFILES: Mapping[str, FirmwareProfile] = MappingProxyType(
    {
        p.name: p
        for p in (
            FirmwareProfile(
                "no-standby",
                "Never enters standby: answers commands without a break at any time (after"
                " 100 ms of marking, after a command to another address) and so also after a"
                " 5 ms spacing pulse.",
                ("standby-ignored", "stays-awake-after-foreign"),
            ),
            FirmwareProfile(
                "unkn-replies",
                "Answers every command it does not know or serve with 'aUNKN<CR><LF>'"
                " instead of silence or the unsupported form.",
                ("unknown-command-text",),
            ),
            FirmwareProfile(
                "crc-ignored",
                "Takes the CRC commands for their plain twins: aMC!, aCC!, aRCn! and the CRC"
                " metadata commands are answered like aM!, aC!, aRn! and aIM_nnn!, no CRC.",
                (
                    "crc-missing",
                    "continuous-crc-missing",
                    "unsupported-rc-without-crc",
                    "metadata-crc-missing",
                ),
            ),
            FirmwareProfile(
                "slow-15ms",
                "Every reply starts a fixed 15.0 ms after the command's last stop bit: inside"
                " the 15.40 ms limit (a slow but conforming sensor; nothing may FAIL).",
                quirks={"reply_delay": 15.0e-3},
            ),
            FirmwareProfile(
                "prompt-sr",
                "Measures at once yet announces ttt = 001 for M and V: the service request"
                " follows the atttn reply after 8.4 ms (legal, R-4.4.6-02/04), where a"
                " recorder that does not listen before it talks starts its next break into it.",
                quirks={"announce_ttt": 1, "ready_after": 8.4e-3},
            ),
            FirmwareProfile(
                "quick-ready",
                "Finishes every M/V measurement 20 ms after its atttn reply, whatever ttt says:"
                " the service request comes long before ttt (legal, though R-4.4.5-09 may"
                " warn), so a break sent after it finds nothing to abort.",
                quirks={"ready_after": 20e-3},
            ),
            FirmwareProfile(
                "d1-only",
                "Puts the data of M/V only on D1; D0 answers with no values.",
                ("groups-start-at-d1",),
            ),
        )
    }
)


def profile_settings(names: tuple[str, ...]) -> tuple[tuple[str, ...], dict[str, Any]]:
    """The faults and quirks of the named profiles together (KeyError naming an unknown)."""
    faults: list[str] = []
    quirks: dict[str, Any] = {}
    for name in names:
        if name not in PROFILES:
            raise KeyError(f"unknown profile {name!r}")
        faults.extend(PROFILES[name].faults)
        quirks.update(PROFILES[name].quirks)
    return tuple(faults), quirks
