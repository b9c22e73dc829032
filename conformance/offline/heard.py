"""What a recording shows, read once for the passive cases: the role-neutral view, the tool
recorder's records rebuilt from it, the rule set, and the notes a reader of the verdicts needs.

:class:`HeardSensors` (sensor rules, on what the sensors sent) and :class:`HeardRecorder`
(recorder rules, on what the recorder sent) stand where the live sessions stand for the
reports: ``verdicts.json``'s ``dut`` block reads the same attributes (address, identity,
version, assumptions), so the passive run's reports have the live run's shape.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

from ..declaration import normalise_version
from ..dut import DutClaim, Session, sensor_claim
from ..judges.exchanges import identification
from ..judges.timing import StampUncertainty
from ..preconditions import NOT_SEEN as _NOT_SEEN
from ..protocol.commands import Kind
from ..protocol.responses import Identification
from ..protocol.version import V14, VERSIONS, format_version, is_v14
from ..replay.recording_link import RecordingLink
from ..tool_recorder.records import Exchange, Measurement
from ..view.segments import memo
from .bus_indexes import spill_indexes
from .bus_sensors import BusSensor, SensorsOn, sensors_on
from .held_exchanges import HeldExchanges
from .held_measurements import HeldMeasurements
from .sensor_windows import (
    AMBIGUITIES_SHOWN,
    BusWindows,
    SensorRecords,
    bus_windows,
    disturbance,
    sensor_records,
    stamp_uncertainty_of,
)

#: What a rule whose stimulus the recording lacks is told (INCONCLUSIVE, never PASS): the
#: wording of the ``heard`` precondition (conformance/preconditions.py), re-exported here.
NOT_SEEN = _NOT_SEEN


def recording_notes(link: RecordingLink, bus: BusWindows) -> list[str]:
    """The decode figures and polarity (a capture), and how many splits the view had to make
    that the wire does not settle (direction, framing), with the first few reasons (the
    bus pass's count and first few, :class:`~.sensor_windows.Ambiguities`)."""
    notes = list(link.notes)
    if link.decoded is not None:
        from .judge import describe_decode  # the capture side, only for a capture

        notes += describe_decode(link.decoded)
    count, first = bus.ambiguities
    if count:
        shown = "; ".join(first)
        extra = count - AMBIGUITIES_SHOWN
        more = f" (+{extra} more)" if extra > 0 else ""
        notes.append(f"{count} ambiguous split(s) in the recording: {shown}{more}")
    else:
        notes.append("no ambiguous split in the recording (every direction and reply is clear)")
    return notes


@dataclass
class Heard(Session):
    """What both roles' passive cases share: the recording (no view of it: neither role's
    cases nor the reports read the whole recording's view, issue 22)."""

    link: RecordingLink
    forced_version: str | None = None
    assumptions: list[str] = field(default_factory=list)
    address: str | None = None
    identity: Identification | None = None
    ident_exchange: Exchange | None = None
    address_notes: list[str] = field(default_factory=list)
    #: every sensor on the bus (``--address`` or not), for ``verdicts.json``'s ``duts``
    on_bus: list[BusSensor] = field(default_factory=list)

    def bus_sensors(self) -> list[tuple[str, DutClaim]]:
        return [(s.address, s.claim()) for s in self.on_bus]

    @property
    def uncertainty(self) -> float:
        return self.link.uncertainty

    @property
    def stamp_uncertainty(self) -> StampUncertainty:
        """The recording's uncertainty; for a host-stamped transcript also a (flat) local
        figure, which makes the timing judges treat it as the real-time link it was: a rare
        deviation among many conforming observations may be a stall of the recording host,
        decided by where it falls, and INCONCLUSIVE when that cannot tell (a recording cannot
        be probed again). A monitor's transcript FAILed R-7.0-12 on one stalled stamp."""
        return stamp_uncertainty_of(self.link)

    @property
    def version(self) -> str:
        """The rule set: --sdi-version > the ``ll`` of an ``aI!`` reply seen > v1.4 (said)."""
        if self.forced_version:
            return self.forced_version
        if self.identity is not None and self.identity.version in VERSIONS:
            return self.identity.version
        return V14

    @property
    def is_v14(self) -> bool:
        return is_v14(self.version)


@dataclass
class HeardSensors(Heard):
    """The sensor rules' records: every exchange and measurement the recording shows (of
    sensor ``address`` only, when one was given), and its replies' timing and framing
    findings (``records``: the sensor pass, :func:`~.sensor_windows.sensor_records`)."""

    #: a list, or the sensor pass's held exchanges (:mod:`.held_exchanges`, read-only)
    exchanges: Sequence[Exchange] = field(default_factory=list)
    #: a list, or the sensor pass's held measurements (:mod:`.held_measurements`, read-only)
    measurements: Sequence[Measurement] = field(default_factory=list)
    records: SensorRecords | None = None

    def of_kind(self, *kinds: Kind, whole: bool = False) -> list[Measurement]:
        """The recorded measurements of ``kinds``; ``whole``: only those the recorder let
        run to their data (their wait and data rules are judged only on those). Of held
        measurements, only those made."""
        if isinstance(self.measurements, HeldMeasurements):
            return self.measurements.of_kinds(kinds, whole)
        return [
            m
            for m in self.measurements
            if m.command.kind in kinds and not (whole and m.aborted_by is not None)
        ]

    def exchanges_of(self, *kinds: Kind) -> list[Exchange]:
        """The recorded exchanges whose command is of ``kinds``, in order (of held exchanges,
        only those made)."""
        if isinstance(self.exchanges, HeldExchanges):
            return self.exchanges.of_kinds(kinds)
        return [x for x in self.exchanges if x.command is not None and x.command.kind in kinds]

    def claim(self) -> DutClaim:
        return sensor_claim(self.identity, self.ident_exchange, self.forced_version, self.version)


@dataclass
class HeardRecorder(Heard):
    """The recorder rules read the whole bus (``--address`` does not narrow them)."""


def sensors_records(link: RecordingLink, address: str | None) -> SensorRecords:
    """``address``'s records and timing findings (None: every sensor's together), read by
    the sensor pass (:func:`~.sensor_windows.sensor_records`) once per loaded recording and
    address, over the windows the bus pass (:func:`bus_of`) found: no whole-run view,
    segments or records are made. Made again if :func:`release_records` let them go: they
    are a pure function of the recording."""
    held = memo(link, "_sensor_records", len(link.transcript.events), dict)
    if address not in held:
        held[address] = sensor_records(link, bus_of(link), address)
    return held[address]


def bus_of(link: RecordingLink) -> BusWindows:
    """The bus pass over ``link``'s recording (:func:`~.sensor_windows.bus_windows`), made
    once per loaded recording: the sensors on the bus, their decode-quality notes, the
    ambiguous splits and where the windows are (written out with the recording's events
    once the pass is done: :mod:`.bus_indexes`)."""
    bus = bus_windows(link)
    spill_indexes(bus)
    return bus


def release_records(link: RecordingLink, keep: Collection[str]) -> None:
    """Drop the records read from ``link`` that no later run reads: every sensor's but
    those of the addresses in ``keep`` (the sensors still to be judged), and every
    sensor's together. A passive judgement of a bus judges its sensors one after the other
    and the recorder last, which reads none of them; keeping every sensor's records to the
    end held them all at the recorder run's peak (about 0.4 MB a minute of a busy capture).
    A run that asks again gets them read again, the same (:func:`sensors_records`), so
    what is judged never depends on what was released."""
    held = link.__dict__.get("_sensor_records")
    if held is None:
        return
    mine: dict[str | None, SensorRecords] = held[1]
    for address in [a for a in mine if a is None or a not in keep]:
        del mine[address]


def bus_sensors(link: RecordingLink) -> list[BusSensor]:
    """:func:`sensors_on` the recording (found once per loaded recording, by the bus pass)."""
    return list(bus_of(link).sensors)


def settle_bus(link: RecordingLink) -> None:
    """Make what the runs of a bus's sensors read of every sensor (the sensors on the bus,
    each one's decode-quality note: the bus pass) before the first run."""
    bus_of(link)


def _shared_notes(link: RecordingLink) -> list[str]:
    """:func:`recording_notes`, made once per loaded recording (each run gets its own list)."""
    return list(
        memo(
            link, "_notes", len(link.transcript.events), lambda: recording_notes(link, bus_of(link))
        )
    )


def hear_sensors(link: RecordingLink, address: str | None, version: str | None) -> HeardSensors:
    bus = bus_of(link)
    records = sensors_records(link, address)
    heard = HeardSensors(
        link,
        forced_version=normalise_version(version) if version else None,
        address=address,
        exchanges=records.exchanges,  # (read-only: no copy)
        measurements=records.measurements,  # (read-only: no copy)
        records=records,
        on_bus=list(bus.sensors),
    )
    cut = sum(1 for m in heard.measurements if m.aborted_by is not None)
    heard.assumptions = _shared_notes(link)
    if link.decoded is not None:  # a capture: how well this sensor's own characters read
        # all the sensors together, or one (an address that never answered: no note)
        quality = bus.all_quality if address is None else bus.qualities.get(address)
        if quality is not None:
            heard.assumptions.append(quality)
    if cut:
        heard.assumptions.append(
            f"{cut} recorded measurement(s) interrupted by the recorder (a command before the "
            "service request or ttt, or no aD0! next; for a concurrent one, a command to the "
            "same sensor before its aD0!): their replies are judged, not their waits or data"
        )
    if address is not None:
        on = ", ".join(s.address for s in heard.on_bus)
        several = len(heard.on_bus) > 1
        why = f"of the {len(heard.on_bus)} sensors on the bus: {on}" if several else "--address"
        heard.assumptions.append(f"sensor rules judged on sensor {address!r} only ({why})")
    _identify(heard)
    return heard


def _identify(heard: HeardSensors) -> None:
    """The rule set from an ``aI!`` reply seen (the chosen sensor's, else the first sensor
    that answered one), unless --sdi-version forced it; v1.4 otherwise, said so."""
    for ex in heard.exchanges_of(Kind.IDENTIFY):
        if ex.answered and ex.command is not None:
            ident, _ = identification(ex, ex.command.address)
            if ident is not None and ident.version in VERSIONS:
                heard.identity, heard.ident_exchange = ident, ex
                heard.address = heard.address or ex.command.address
                break
    if heard.forced_version:
        heard.assumptions.append(f"rule set v{format_version(heard.version)} (--sdi-version)")
    elif heard.identity is None:
        heard.assumptions.append("no aI! reply with a usable version seen; judging against v1.4")
    else:
        v = heard.identity.version
        heard.assumptions.append(
            f"rule set v{format_version(v)} from the aI! reply of sensor {heard.address!r}"
        )


def hear_recorder(link: RecordingLink, version: str | None) -> HeardRecorder:
    """The recorder rules' session: no view (its cases read
    :func:`~.recorder_windows.recorder_findings`), the notes and sensors of the bus pass."""
    heard = HeardRecorder(
        link,
        forced_version=normalise_version(version) if version else None,
        on_bus=bus_sensors(link),
    )
    heard.assumptions = _shared_notes(link)
    if heard.forced_version is None:
        heard.assumptions.append("the recorder's SDI-12 version is not on the wire; judging v1.4")
    return heard


__all__ = [
    "AMBIGUITIES_SHOWN",
    "NOT_SEEN",
    "BusSensor",
    "Heard",
    "HeardRecorder",
    "HeardSensors",
    "SensorsOn",
    "bus_of",
    "bus_sensors",
    "disturbance",
    "hear_recorder",
    "hear_sensors",
    "recording_notes",
    "release_records",
    "sensors_on",
    "sensors_records",
    "settle_bus",
]
