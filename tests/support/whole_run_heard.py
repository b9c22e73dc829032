"""The whole-run path of the passive sensor session, ``conformance/offline/heard.py`` as
base-s61 had it (its memo keys renamed ``_oracle_*`` so that it shares nothing with the
package's on one loaded recording): the oracle ``tests/offline/test_sensor_windows.py``
judges the windowed sessions (``conformance.offline.sensor_windows``) against. It cuts the
whole view, the whole run's segments and records, as the product did before issue 22's
windowed sensor run. What is no whole-run matter it takes from the package (the session's
base class, the sensors-on fold, a measurement's ``collected``), each a function of what it
is given alone."""

from __future__ import annotations

import math
import re
from bisect import bisect_left
from collections.abc import Collection, Iterator
from dataclasses import dataclass, field
from itertools import islice, takewhile
from operator import le
from typing import Protocol, TypeVar

from conformance.declaration import normalise_version
from conformance.dut import DutClaim, sensor_claim
from conformance.judges.exchanges import identification
from conformance.offline.bus_sensors import BusSensor, sensors_on
from conformance.offline.decode_quality import decode_quality, rate_of, sensor_characters
from conformance.offline.heard import Heard
from conformance.offline.sensor_windows import collected
from conformance.preconditions import NOT_SEEN as _NOT_SEEN
from conformance.protocol.commands import (
    CONCURRENT_KINDS,
    SERVICE_REQUEST_KINDS,
    Kind,
)
from conformance.protocol.version import VERSIONS, format_version
from conformance.replay.recording_link import RecordingLink
from conformance.tool_recorder.records import Exchange, Measurement
from conformance.transcript import Event
from conformance.view.rebuilt_records import Rebuilt, rebuild_records, rebuilt_exchanges
from conformance.view.runs import Segment, transcript_segments, transcript_view
from conformance.view.segments import TranscriptView, Transmission, memo

#: ambiguity reasons quoted in the notes (the count is always given)
AMBIGUITIES_SHOWN = 3
#: What a rule whose stimulus the recording lacks is told (INCONCLUSIVE, never PASS): the
#: wording of the ``heard`` precondition (conformance/preconditions.py), re-exported here.
NOT_SEEN = _NOT_SEEN
T = TypeVar("T")


def recording_notes(link: RecordingLink, view: TranscriptView) -> list[str]:
    """The decode figures and polarity (a capture), and how many splits the view had to make
    that the wire does not settle (direction, framing), with the first few reasons."""
    notes = list(link.notes)
    if link.decoded is not None:
        from conformance.offline.judge import describe_decode  # a capture's side

        notes += describe_decode(link.decoded)
    found = view.ambiguities()
    if found:
        shown = "; ".join(str(a) for a in found[:AMBIGUITIES_SHOWN])
        extra = len(found) - AMBIGUITIES_SHOWN
        more = f" (+{extra} more)" if extra > 0 else ""
        notes.append(f"{len(found)} ambiguous split(s) in the recording: {shown}{more}")
    else:
        notes.append("no ambiguous split in the recording (every direction and reply is clear)")
    return notes


@dataclass
class HeardSensors(Heard):
    """The sensor rules' records: every exchange and measurement the recording shows (of
    sensor ``address`` only, when one was given), and the timing cut of the same traffic."""

    exchanges: list[Exchange] = field(default_factory=list)
    measurements: list[Measurement] = field(default_factory=list)
    segments: list[Segment] = field(default_factory=list)
    view: TranscriptView | None = None  # the whole view (the product's sessions hold none)

    def of_kind(self, *kinds: Kind, whole: bool = False) -> list[Measurement]:
        """The recorded measurements of ``kinds``; ``whole``: only those the recorder let
        run to their data (their wait and data rules are judged only on those)."""
        return [
            m
            for m in self.measurements
            if m.command.kind in kinds and not (whole and m.aborted_by is not None)
        ]

    def exchanges_of(self, *kinds: Kind) -> list[Exchange]:
        return [x for x in self.exchanges if x.command is not None and x.command.kind in kinds]

    def claim(self) -> DutClaim:
        return sensor_claim(self.identity, self.ident_exchange, self.forced_version, self.version)


@dataclass
class HeardRecorder(Heard):
    """The recorder rules read the whole bus (``--address`` does not narrow them)."""

    view: TranscriptView | None = None  # the whole view (the product's sessions hold none)


def heard_records(link: RecordingLink) -> tuple[TranscriptView, Rebuilt]:
    """The recording's view and the records rebuilt from it, cut once per loaded recording:
    the count of sensors on it, each sensor's run and the recorder's read the same (cut
    again for each, an hour's capture cost seconds a run, N + 2 times for N sensors). Kept
    while the transcript keeps its length (a recording only grows while it is read)."""

    def cut() -> tuple[TranscriptView, Rebuilt]:
        view = transcript_view(link.transcript)  # the reports' evidence reads it too
        return view, rebuild_records(view, uncertainty=link.uncertainty)

    return memo(link, "_oracle_heard_records", len(link.transcript.events), cut)


@dataclass(frozen=True)
class _PerSensor:
    """The records and segments of the sensors asked for so far (each made alone,
    :func:`_per_sensor`)."""

    exchanges: dict[str, list[Exchange]]
    measurements: dict[str, list[Measurement]]
    segments: dict[str, list[Segment]]


def _per_sensor(link: RecordingLink, address: str | None = None) -> _PerSensor:
    """``address``'s records: rebuilt for that sensor alone
    (:func:`~conformance.view.rebuilt_records.rebuild_records` ``only``), the same records
    the whole run's rebuild gives it, so that a bus's first sensor run does not hold every
    sensor's (15 MB at an hour of a busy capture); and its segments: those of the view's
    transmissions whose text starts with its address, made alone too (each segment is made
    from its own transmission, so they are the whole run's segments of that address, in
    order). Every sensor's segments split from the whole run's cut held that cut (11.5 MB at
    an hour) from the first sensor's run to the end; a run reads its own sensor's only.
    Made again if :func:`release_records` let them go: they are a pure function of the
    recording."""
    mine = memo(
        link, "_oracle_per_sensor", len(link.transcript.events), lambda: _PerSensor({}, {}, {})
    )
    if address is not None and address not in mine.exchanges:
        view = transcript_view(link.transcript)
        rebuilt = rebuild_records(view, uncertainty=link.uncertainty, only=address)
        mine.exchanges[address] = rebuilt.exchanges
        mine.measurements[address] = rebuilt.measurements
        mine.segments[address] = [Segment.of(t) for t in _sent_to(link, view, address)]
    return mine


def _sent_to(link: RecordingLink, view: TranscriptView, address: str) -> list[Transmission]:
    """The view's transmissions whose text starts with ``address`` (one character: a
    sensor's), in order; for any other string, those whose first character is it (an empty
    one: those with no text), as a split by first character answered."""
    if len(address) != 1 or address == "\0":
        return [t for t in view.transmissions if t.text[:1] == address]
    firsts = memo(link, "_oracle_firsts", len(link.transcript.events), lambda: _firsts(view))
    return [view.transmissions[m.start()] for m in re.finditer(re.escape(address), firsts)]


def _firsts(view: TranscriptView) -> str:
    """The first character of each transmission's text, in order ("\\0" for an empty one):
    which transmissions are to a sensor, read once for every sensor's run (each asking every
    transmission's text cost an hour's capture 0.1 s a run)."""
    return "".join([t.text[:1] or "\0" for t in view.transmissions])


def release_records(link: RecordingLink, keep: Collection[str]) -> None:
    """Drop the records rebuilt from ``link`` that no later run reads: the whole lists, and
    every sensor's share but those of the addresses in ``keep`` (the sensors still to be
    judged). A passive judgement of a bus judges its sensors one after the other and the
    recorder last, which reads the view and the segments only; keeping every sensor's
    records to the end held them all at the recorder run's peak (about 0.4 MB a minute of
    a busy capture). A run that asks again gets them rebuilt, the same (:func:`_per_sensor`,
    :func:`heard_records`), so what is judged never depends on what was released."""
    link.__dict__.pop("_oracle_heard_records", None)
    held = link.__dict__.get("_oracle_per_sensor")
    if held is None:
        return
    mine: _PerSensor = held[1]
    for address in [a for a in mine.exchanges if a not in keep]:
        mine.exchanges.pop(address, None)
        mine.measurements.pop(address, None)
        mine.segments.pop(address, None)


def bus_sensors(link: RecordingLink) -> list[BusSensor]:
    """:func:`sensors_on` the recording (found once per loaded recording)."""
    return _bus_sensors(link)


def settle_bus(link: RecordingLink) -> None:
    """Make what the runs of a bus's sensors read of every sensor's records (the sensors on
    the bus, each one's decode-quality note) before the first run, from the exchanges made
    one at a time, and let go of any whole-run records: each sensor's run then rebuilds its
    own alone (:func:`_per_sensor`), and no run holds every sensor's at once."""
    _bus_sensors(link)
    if link.decoded is not None:
        _qualities(link)
    link.__dict__.pop("_oracle_heard_records", None)


def _qualities(link: RecordingLink) -> dict[str, str | None]:
    """Each sensor's decode-quality note, by address, all made in one pass: the lookup of
    every character's bit-rate error (:class:`~.decode_quality.CharRates`, 16 bytes a
    character) is built once and not kept."""

    def build() -> dict[str, str | None]:
        events = link.transcript.events
        rates = rate_of(link.decoded, events)
        return {
            a: decode_quality(link.decoded, events, chars, f"sensor {a!r}", rates=rates)
            for a, chars in _characters_by_sensor(link).items()
        }

    return memo(link, "_oracle_qualities", len(link.transcript.events), build)


def _exchanges(link: RecordingLink) -> Iterator[Exchange]:
    """Every exchange of the recording in wire order, made one at a time
    (:func:`~conformance.view.rebuilt_records.rebuilt_exchanges`): the same exchanges
    :func:`heard_records` holds, for what reads each once."""
    return rebuilt_exchanges(transcript_view(link.transcript), uncertainty=link.uncertainty)


def _characters_by_sensor(link: RecordingLink) -> dict[str, list[Event]]:
    """:func:`~.decode_quality.sensor_characters` of each sensor's exchanges (by the first
    character of their text, in order of first appearance), read from the exchanges one at
    a time."""
    found: dict[str, list[Event]] = {}
    for x in _exchanges(link):
        found.setdefault(x.text[:1], []).extend(sensor_characters([x]))
    return found


def _shared_notes(link: RecordingLink, view: TranscriptView) -> list[str]:
    """:func:`recording_notes`, made once per loaded recording (each run gets its own list)."""
    return list(
        memo(
            link, "_oracle_notes", len(link.transcript.events), lambda: recording_notes(link, view)
        )
    )


def _bus_sensors(link: RecordingLink) -> list[BusSensor]:
    """:func:`sensors_on` the recording's exchanges, found once per loaded recording."""

    def find() -> list[BusSensor]:
        return sensors_on(_exchanges(link))

    return list(memo(link, "_oracle_on_bus", len(link.transcript.events), find))


def hear_sensors(link: RecordingLink, address: str | None, version: str | None) -> HeardSensors:
    view = transcript_view(link.transcript)  # the one heard_records rebuilt records from
    if address is None:
        _view, rebuilt = heard_records(link)
        segments = list(transcript_segments(link.transcript))
        exchanges, measurements = list(rebuilt.exchanges), list(rebuilt.measurements)
    else:
        mine = _per_sensor(link, address)
        exchanges = list(mine.exchanges.get(address, ()))
        measurements = list(mine.measurements.get(address, ()))
        segments = list(mine.segments.get(address, ()))
    heard = HeardSensors(
        link,
        view=view,
        forced_version=normalise_version(version) if version else None,
        address=address,
        exchanges=exchanges,
        measurements=measurements,
        segments=segments,
        on_bus=_bus_sensors(link),
    )
    for m in heard.measurements:
        m.aborted_by = disturbance(m, view)
    cut = sum(1 for m in heard.measurements if m.aborted_by is not None)
    heard.assumptions = _shared_notes(link, view)
    if link.decoded is not None:  # a capture: how well this sensor's own characters read
        who = f"sensor {address!r}" if address is not None else "the sensor(s)"
        found = _qualities(link) if address is not None else {}
        if address in found:
            quality = found[address]
        else:  # all the sensors, or an address that never answered
            chars = sensor_characters(heard.exchanges)
            quality = decode_quality(link.decoded, link.transcript.events, chars, who)
        if quality is not None:
            heard.assumptions.append(quality)
    if cut:
        heard.assumptions.append(
            f"{cut} recorded measurement(s) interrupted by the recorder (a command before the "
            "service request or ttt, or no aD0! next; for a concurrent one, a command to the "
            "same sensor before its aD0!): their replies are judged, not their waits or data"
        )
    if address is not None:
        bus = ", ".join(s.address for s in heard.on_bus)
        several = len(heard.on_bus) > 1
        why = f"of the {len(heard.on_bus)} sensors on the bus: {bus}" if several else "--address"
        heard.assumptions.append(f"sensor rules judged on sensor {address!r} only ({why})")
    _identify(heard)
    return heard


class _Timed(Protocol):
    @property
    def start(self) -> float: ...


_Item = TypeVar("_Item", bound=_Timed)


def _from(
    view: TranscriptView, items: list[_Item], at: float, before: float = math.inf
) -> Iterator[_Item]:
    """``items`` (a view's transmissions or breaks) starting at or after ``at``, in order;
    given ``before``, the caller wants only those starting before it and may get no more.
    One recording's items are in time order, so this is a bisection and a few items, not a
    scan of the whole recording for each measurement (quadratic over an hour of aM! polls);
    items out of order (never seen) are all scanned, as before."""
    key = "_transmission_starts" if items is view.transmissions else "_break_starts"
    starts = memo(view, key, len(items), lambda: _starts_if_ordered(items))
    if starts is None:
        return (t for t in items if t.start >= at)
    found = islice(items, bisect_left(starts, at), None)
    return takewhile(lambda t: t.start < before, found) if before < math.inf else found


def _starts_if_ordered(items: list[_Item]) -> list[float] | None:
    starts = [t.start for t in items]
    return starts if all(map(le, starts, starts[1:])) else None


def disturbance(m: Measurement, view: TranscriptView) -> str | None:
    """What the recorder did that keeps ``m``'s wait and data from being the sensor's own
    doing: a transmission or a break before the service request (or ttt) of an aM!-type
    measurement, or anything but its aD0!/aDB0! as the next transmission (after an aM!-type
    measurement the recorder talks to no one else, R-4.4.5-06). A concurrent measurement
    (C/CC/Cn/CCn/HA/HB) is disturbed only by a command to its own sensor before its aD0!
    (it aborts it, R-4.4.7.1-01, R-5.3-01): traffic to other sensors is what it is for, and
    a break does not abort it either (R-4.4.7-05, decision A4), so neither sets it aside.
    The rebuilt records follow its data the same way. None: undisturbed."""
    if m.reply_end is None or m.ttt is None:
        return "no usable reply"
    reply_end = m.reply_end
    if m.command.kind in SERVICE_REQUEST_KINDS and m.ttt:
        due = m.service_request_end or reply_end + m.ttt
        early = next(
            (t for t in _from(view, view.transmissions, reply_end, due) if t.start < due), None
        )
        if early is not None:
            return early.text
        if any(reply_end <= b.start < due for b in _from(view, view.breaks, reply_end, due)):
            return "break"  # a break aborts an aM!-type measurement (R-4.4.5-10)
    later = _from(view, view.transmissions, reply_end)
    if m.command.kind in CONCURRENT_KINDS:
        later = (t for t in later if t.address == m.command.address)
    first = next(later, None)
    if first is None:
        return "nothing more sent"
    index = first.data_index
    if first.address != m.command.address or index is None or index[1] != 0:
        # the records follow a measurement's data only while nothing else comes between
        return first.text
    if not collected(m):
        return "the recorder stopped asking for data while values were due"
    return None


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
    view = transcript_view(link.transcript)  # the recorder rules read no rebuilt record
    heard = HeardRecorder(
        link,
        view=view,
        forced_version=normalise_version(version) if version else None,
        on_bus=_bus_sensors(link),
    )
    heard.assumptions = _shared_notes(link, view)
    if heard.forced_version is None:
        heard.assumptions.append("the recorder's SDI-12 version is not on the wire; judging v1.4")
    return heard
