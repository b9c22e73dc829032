"""What a run knows of its device under test, whichever session judged it.

A run holds one session: the sensor role's (the tool records from a live sensor), the recorder
role's (the tool plays sensors to a live recorder), or a passive one (a recording heard after
the fact, either role). The run, its reports and the plugin read them all through
:class:`Session`, so none of them needs to know which it has, and no session sets attributes
it has no use for so that a report can read them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from .links.host_stall import Stall
    from .protocol.responses import Identification
    from .results import CaseRecord
    from .tool_recorder.records import Exchange


@dataclass(frozen=True)
class DutClaim:
    """What the DUT said about itself: its ``aI!`` reply (parsed, and as heard) and the rule
    set the run judged it by *as a claim* (None when nothing answered ``aI!`` and nobody
    forced a rule set: the run then assumed one, which is not the DUT's claim)."""

    identity: Identification | None = None
    reply: str | None = None
    version: str | None = None


class Session(Protocol):
    """A run's session, as the run, the reports and the plugin read it. Sessions subclass it
    for the defaults of the optional parts."""

    address: str | None  # the DUT's address (None: the recorder role has none)
    assumptions: list[str]  # what the run took for granted, for the reports
    address_notes: list[str]  # what every address change left behind (design.md 7)
    # (attributes or properties, as each session keeps them)
    version: str  # the rule set the DUT is judged by ("13"/"14")
    uncertainty: float  # s: the timing uncertainty every timing verdict carries now

    def claim(self) -> DutClaim:
        """What the DUT said about itself, for the report's DUT block."""
        return DutClaim(version=self.version)

    def apply_declaration(self, record: CaseRecord) -> None:
        """Read a case's findings with what the DUT declared it cannot do (default: no
        declaration changes a finding after the case)."""

    def link_facts(self) -> dict[str, Any]:
        """What the session adds to the report's link block (the tool recorder's collisions,
        a harness's stderr); empty by default."""
        return {}

    def bus_sensors(self) -> list[tuple[str, DutClaim]] | None:
        """Every sensor the run saw on the bus, in address order, with what each said about
        itself (``verdicts.json``'s ``duts``). A passive run lists the sensors its recording
        shows; a live run drives one DUT and gives None (the key is then left out)."""
        return None

    def worst_lateness(self) -> float:
        """How far a line the tool kept in real time fell behind its schedule (s); 0 when
        the tool keeps no such line."""
        return 0.0

    def unexplained_lateness(self) -> float:
        """:meth:`worst_lateness` of the frames due outside every stall of the tool's host
        the line noted (truth32): what no note explains."""
        return self.worst_lateness()

    def recorder_in_process(self) -> bool:
        """Whether the recorder judged acts through this tool's process (its golden recorder,
        a harness it drives): a stall of the tool's host holds it up too (truth34)."""
        return True

    def noted_stalls(self) -> list[Stall]:
        """The stalls of the tool's host that such a line noted in its transcript (truth34):
        none where the tool keeps no such line."""
        return []


def sensor_claim(
    identity: Identification | None,
    exchange: Exchange | None,
    forced_version: str | None,
    version: str,
) -> DutClaim:
    """A sensor's claim: its ``aI!`` reply if one was heard, and the rule set only when the
    reply named one or the user forced it (else the run's v1.4 is an assumption)."""
    reply = exchange.reply_text if exchange is not None and exchange.answered else None
    return DutClaim(identity, reply, version if identity or forced_version else None)
