"""Measurement state of the emulator: the measurement running now and the data buffer.

Kept apart from the line handling because the rules are different in kind: section 7 is about
stamps, this is about what a D command returns. A running measurement becomes data when its
ready time has passed (checked lazily against the stamps the emulator is given); data stay
until the next measurement-starting command (R-4.4.5-10).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..protocol.commands import Command, Kind, data_index_max
from ..protocol.values import pack_values
from .behaviour import Behaviour
from .profile import MeasurementSpec


@dataclass
class Run:
    """A measurement that has been started and is not complete yet."""

    command: Command
    spec: MeasurementSpec | None
    ready_at: float

    @property
    def concurrent(self) -> bool:
        return self.command.is_concurrent


@dataclass
class DataSet:
    """What D/DB commands return until the next measurement starts.

    ``pages`` is the ``<values>`` text of D0, D1, ...; ``packets`` the HB packets of DB0,
    DB1, ...; ``crc`` whether D replies carry a CRC. An aborted measurement leaves a DataSet
    with no pages (the empty ``a<CR><LF>`` reply, R-4.4.5.1-02).
    """

    source: Command | None
    pages: list[str] = field(default_factory=list)
    packets: list[tuple[int, list[int | float]]] = field(default_factory=list)
    crc: bool = False
    reads: dict[int, int] = field(default_factory=dict)

    @property
    def binary(self) -> bool:
        return self.source is not None and self.source.kind is Kind.HIGH_VOLUME_BINARY

    @property
    def max_index(self) -> int:
        """Highest D index the measurement type allows (D0..D9, or D999 after HA)."""
        return data_index_max(self.source)

    @property
    def fully_read(self) -> bool:
        """Every page (or packet) has been sent at least once."""
        total = len(self.packets) if self.binary else len(self.pages)
        return total > 0 and all(self.reads.get(i, 0) > 0 for i in range(total))

    def note_read(self, index: int) -> int:
        """Count a read of ``index``; return how often it was read before."""
        before = self.reads.get(index, 0)
        self.reads[index] = before + 1
        return before

    def emptied(self) -> DataSet:
        """The same measurement with its values gone (empty replies, CRC form kept)."""
        return DataSet(self.source, crc=self.crc)


def empty_data(command: Command | None) -> DataSet:
    return DataSet(command, crc=bool(command and command.returns_crc))


def value_limit(command: Command, behaviour: Behaviour) -> int:
    """``<values>`` characters per D reply after ``command`` (R-4.4-05, R-5.1-03)."""
    if command.kind is Kind.HIGH_VOLUME_ASCII:
        return behaviour.limit_high_volume
    if command.is_concurrent:
        return behaviour.limit_concurrent
    return behaviour.limit_measure


def paginate(values: list[str], limit: int, slack: int = 0, split: bool = False) -> list[str]:
    """Group values into D pages.

    Conforming: greedy, whole values, as many as fit (``values.pack_values``). ``slack`` leaves
    that many values out of each page that holds more than one (an under-filled reply);
    ``split`` fills every page to exactly ``limit`` characters, cutting a value in two.
    """
    if split:
        text = "".join(values)
        return [text[i : i + limit] for i in range(0, len(text), limit)]
    if slack <= 0:
        return pack_values(values, limit)
    out: list[str] = []
    queue = list(values)
    while queue:
        take, length = 0, 0
        while take < len(queue) and length + len(queue[take]) <= limit:
            length += len(queue[take])
            take += 1
        if take > 1:
            take = max(1, take - slack)
        out.append("".join(queue[: max(take, 1)]))
        del queue[: max(take, 1)]
    return out


def complete(run: Run, behaviour: Behaviour) -> DataSet:
    """The data a finished measurement leaves in the buffer."""
    command, spec = run.command, run.spec
    data = empty_data(command)
    if spec is None or behaviour.drop_all_values:
        return data
    if command.kind is Kind.HIGH_VOLUME_BINARY:
        data.packets = [(int(p.dtype), list(p.values)) for p in spec.packets]
        return data
    concurrent = command.is_concurrent
    data.pages = paginate(
        list(spec.values),
        value_limit(command, behaviour),
        slack=0 if concurrent else behaviour.pack_slack,
        split=behaviour.split_values and not concurrent,
    )
    return data
