"""The sensors a recording shows on its bus (moved out of :mod:`.heard`, which re-exports
them, so that the windowed pass over a recording, :mod:`.sensor_windows`, can feed
:class:`SensorsOn` without importing the session it serves)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from ..dut import DutClaim
from ..judges.exchanges import identification
from ..protocol.commands import ADDRESS_CHARS, Kind
from ..protocol.responses import Identification
from ..protocol.version import VERSIONS
from ..tool_recorder.records import Exchange


@dataclass(frozen=True)
class BusSensor:
    """A sensor the recording shows answering: its address and its ``aI!`` reply, if one
    was heard (``identity``: parsed; ``reply``: as heard)."""

    address: str
    identity: Identification | None = None
    reply: str | None = None

    def claim(self) -> DutClaim:
        version = self.identity.version if self.identity is not None else None
        return DutClaim(self.identity, self.reply, version if version in VERSIONS else None)


def sensors_on(exchanges: Iterable[Exchange]) -> list[BusSensor]:
    """The sensors whose replies the recording holds, in address order. A sensor is known by
    the address it first answered at: an accepted ``aAb!`` moves it, not a new sensor (a
    sensor run moves its DUT and back), so its later replies at ``b`` are its own."""
    found = SensorsOn()
    found.add(exchanges)
    return found.sensors()


class SensorsOn:
    """:func:`sensors_on` of a recording read a window at a time (issue 22's windowed
    judge): each window's exchanges :meth:`add`-ed in order, the sensors those of the whole
    recording's exchanges. Carried across windows: where each moved sensor answers now, and
    each sensor heard (with its first valid ``aI!`` reply), nothing of a window's events."""

    def __init__(self) -> None:
        self.moved: dict[str, str] = {}  # address now -> the address it was first heard at
        self.seen: dict[str, BusSensor] = {}

    def add(self, exchanges: Iterable[Exchange]) -> None:
        """The exchanges of the next window of the recording, in order."""
        moved, seen = self.moved, self.seen
        for ex in exchanges:
            said = ex.reply_text[:1] if ex.answered else ""
            if not said or said not in ADDRESS_CHARS or ex.command is None:
                continue
            if ex.command.kind is Kind.CHANGE_ADDRESS and said == ex.command.new_address:
                moved[said] = moved.get(ex.command.address, ex.command.address)
                continue
            home = moved.get(said, said)
            if home not in seen:
                seen[home] = BusSensor(home)
            if ex.command.kind is Kind.IDENTIFY and seen[home].identity is None:
                ident, _ = identification(ex, said)
                if ident is not None and ident.version in VERSIONS:
                    seen[home] = BusSensor(home, ident, ex.reply_text)

    def sensors(self) -> list[BusSensor]:
        """The sensors heard so far, in address order."""
        return [self.seen[a] for a in sorted(self.seen, key=ADDRESS_CHARS.index)]


__all__ = ["BusSensor", "SensorsOn", "sensors_on"]
