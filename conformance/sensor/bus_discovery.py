"""Finding the sensors of a shared bus (issue 23, item 2), before anything is judged.

``--address 0,1,3`` names them, ``--address all`` looks for them: one ``a!`` after a break at
every address (0-9, A-Z, a-z: 62 probes, a few seconds on a real bus), never ``?!``, which every
sensor on the line would answer at once. Each sensor found is asked ``a!`` again with the
retry rules and ``aI!``, so its identification goes into every report of the run.

Two sensors at one address answer the same ``a!`` together: a real line mixes their bits into
characters that fail parity, the simulated bus (which serialises frames) interleaves them into
``00<CR><CR><LF>``. Either is a *bus* fault, not a verdict on a sensor: the run stops and says
so before anything is judged (exit 4: a setup the run cannot use). A single sensor that merely
garbles its reply is not called two: it is found, and its own suite judges the reply.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from ..links.base import Link
from ..protocol.commands import ADDRESS_CHARS
from ..tool_recorder import ToolRecorder
from ..tool_recorder.records import Exchange
from ..transcript import escape

#: ``--address all``: every address a sensor may have, in the standard's order (R-4.3-03/04).
ALL_ADDRESSES = ADDRESS_CHARS


@dataclass(frozen=True)
class FoundSensor:
    """A sensor that answered ``a!`` at its address, and its ``aI!`` reply (None: none)."""

    address: str
    identification: str | None


@dataclass
class BusDiscovery:
    """What the probes found: the sensors, the addresses two sensors share (with why the
    tool says so), the named addresses nothing answered at, and every exchange sent."""

    found: list[FoundSensor] = field(default_factory=list)
    duplicates: list[tuple[str, str]] = field(default_factory=list)
    silent: list[str] = field(default_factory=list)
    exchanges: list[Exchange] = field(default_factory=list)

    @property
    def addresses(self) -> tuple[str, ...]:
        return tuple(s.address for s in self.found)


def two_talkers(exchange: Exchange, address: str) -> str | None:
    """Why the replies to ``exchange`` show two sensors answering at ``address`` (None: they
    do not): characters that fail parity in every answered try (two UARTs' bits mixed), or
    two CRs before the LF, or (``a!``, whose reply is ``a<CR><LF>``) the address twice at
    the start: two replies interleaved."""
    answered = [a for a in exchange.attempts if a.reply_events]
    if not answered or exchange.command is None:
        return None
    said = exchange.command.text()
    ack = said == f"{address}!"
    for attempt in answered:
        text = "".join(chr(e.char7) for e in attempt.reply_events)
        mixed = not all(e.parity_ok for e in attempt.reply_events)
        doubled = (ack and text.startswith(address * 2)) or text.count("\r") > text.count("\n")
        if not (mixed or doubled):
            return None  # one clean-looking try: one talker (a garbled one is judged later)
    shown = escape(exchange.reply_text)
    return (
        f"{said} answered as '{shown}' in "
        f"{len(answered)} tries: two sensors answer at address {address!r}"
    )


def discover_bus(link: Link, addresses: Sequence[str], *, sweep: bool = False) -> BusDiscovery:
    """Probe ``addresses`` on ``link``. ``sweep`` (``--address all``): one ``a!`` at each, the
    retries only where something answered; named addresses get the retry rules at once."""
    master = ToolRecorder(link)
    found = BusDiscovery()
    for address in addresses:
        if sweep:
            probe = master.raw(f"{address}!", break_first=True)
            found.exchanges.append(probe)
            if not probe.answered:
                continue
        ack = master.acknowledge(address)
        found.exchanges.append(ack)
        if not ack.answered:
            found.silent.append(address)
            continue
        ident = master.identify(address)
        found.exchanges.append(ident)
        why = two_talkers(ack, address) or two_talkers(ident, address)
        if why is not None:
            found.duplicates.append((address, why))
            continue
        found.found.append(FoundSensor(address, ident.reply_text if ident.answered else None))
    return found


__all__ = ["ALL_ADDRESSES", "BusDiscovery", "FoundSensor", "discover_bus", "two_talkers"]
