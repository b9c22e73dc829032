"""The passive sensor cases' records, timing and notes read over the recording a window at a
time (issue 22), as :mod:`.recorder_windows` reads the recorder's.

Two passes, neither of which reads a whole-run view, whole-run segments or whole-run
records:

- the **bus pass** (:func:`bus_windows`, once per loaded recording): the windows
  :func:`~conformance.view.windows.stream_window_sides` cuts from the events as they come,
  each window's view read alone and let go, feeding the sensors on the bus
  (:class:`~.bus_sensors.SensorsOn`), each sensor's decode quality and all of them together
  (:class:`~.decode_quality.Quality`), and the ambiguous splits of the notes (a count and
  the first few, :class:`Ambiguities`). Kept of the windows to read them again: where each
  begins, how many transmissions come before it and which windows hold a transmission to
  each sensor (4 bytes each a window, :func:`count_typecode`), and their events' inferred sides
  (1 byte an event, in a :class:`~conformance.event_store.Column` whose full chunks are
  written to a temporary file: an hour's 357,000 sides held 0.36 MB);
- the **sensor pass** (:func:`sensor_records`, once per sensor's run): the windows that hold
  a transmission to that sensor read again (every window when no address narrows the run),
  and those after a measurement of it whose disturbance the next traffic decides
  (:class:`Disturbances`), each window's records rebuilt for that sensor alone (the CRC
  expectations carried), its segments fed to the reply timing and framing folds
  (``judges.wire.ResponseStarts``, ``ReplyGaps``, ``ReplyBitRate``, ``Framing``). Kept:
  the sensor's exchanges and measurements (what the measurement, data, identification and
  extended cases judge, each measurement's ``aborted_by`` set), their events held as
  positions into the loaded store once their window is read (:mod:`.stored_records`: no
  event of the run held as an object), each exchange outside a measurement then a row of
  numbers made again when a case reads it (:mod:`.held_exchanges`, ~36 bytes, not ~1.3 KB),
  each measurement once its ``aborted_by`` is decided a row too, pointing at its exchanges'
  (:mod:`.held_measurements`: its exchanges then let go as objects), and the folds'
  findings.

Every finding, note and record is the whole-run path's (``tests/offline/
test_sensor_windows.py`` runs that path, kept in ``tests/support/whole_run_heard.py``, as
the oracle on the shared captures, busy-bus captures and recordings with sensor faults).
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from itertools import pairwise
from typing import TYPE_CHECKING

from ..event_store import BLOCK, CHUNK, Column, CompactEvents
from ..judges.timing import StampUncertainty
from ..judges.wire import Framing, ReplyBitRate, ReplyGaps, ResponseStarts
from ..links import host_stall
from ..protocol.commands import CONCURRENT_KINDS, SERVICE_REQUEST_KINDS, Kind
from ..protocol.values import split_values
from ..tool_recorder import stalled_reads, validity
from ..tool_recorder.records import Exchange, Measurement
from ..transcript import Event, EventKind
from ..verdicts import Finding
from ..view.rebuilt_records import rebuild_records
from ..view.runs import Segment
from ..view.segments import (
    Ambiguity,
    TranscriptView,
    Transmission,
    memo,
    unanswerable_ambiguity,
    undirected_ambiguity,
)
from ..view.windows import WindowedTransmissions, stream_window_sides, window_view
from .bus_sensors import BusSensor, SensorsOn
from .decode_quality import CharRates, Quality, problems_by_character, sensor_characters
from .held_exchanges import HeldExchanges
from .held_measurements import HeldMeasurements
from .stored_records import Positions, store_records

if TYPE_CHECKING:
    from ..replay.recording_link import RecordingLink

#: ambiguity reasons quoted in the notes (the count is always given)
AMBIGUITIES_SHOWN = 3
LAST_INDEX = 9  # aD9!: the last data command after aM!/aC!
LAST_HV_INDEX = 999  # aD999!/aDB999!: the last after aHA!/aHB!
EMPTY_PACKET = 6  # bytes of a binary packet holding no value (address, size, type, CRC)


def stamp_uncertainty_of(link: RecordingLink) -> StampUncertainty:
    """The recording's uncertainty; for a host-stamped transcript also a (flat) local
    figure, which makes the timing judges treat it as the real-time link it was: a rare
    deviation among many conforming observations may be a stall of the recording host,
    decided by where it falls, and INCONCLUSIVE when that cannot tell (a recording cannot
    be probed again). A monitor's transcript FAILed R-7.0-12 on one stalled stamp."""
    u = link.uncertainty
    if link.host_stamped:
        return StampUncertainty(u, local=lambda _start, _end: u)
    return StampUncertainty(u)


def ordered_plain(events: Sequence[Event]) -> Sequence[Event]:
    """``events`` without notes, by start (stably, as a view reads them): ``events``
    itself where it is so already (a capture's decode: no copy; a compact store asked
    without making its events), else a sorted list."""
    compact = isinstance(events, CompactEvents)
    if compact and not events.has_kind(EventKind.NOTE) and events.in_start_order():
        return events
    plain = events
    if any(e.kind is EventKind.NOTE for e in events):
        plain = [e for e in events if e.kind is not EventKind.NOTE]
    if all(a.start <= b.start for a, b in pairwise(plain)):
        return plain
    return sorted(plain, key=lambda e: e.start)


class Ambiguities:
    """:meth:`~conformance.view.segments.TranscriptView.ambiguities` of a whole recording
    from its windows' views in order: how many, and the first ``shown`` of them as the
    whole view sorts them (by place; ties in the whole view's order: characters of unknown
    direction, the one item of every unanswerable character, the transmissions' splits).
    Carried: counts, the first unanswerable character and at most ``4 * shown`` items."""

    def __init__(self, shown: int) -> None:
        self.shown, self.count, self.unanswerable, self.seq = shown, 0, 0, 0
        self.first: Event | None = None
        self.kept: list[tuple[float, int, int, Ambiguity]] = []

    def add(self, view: TranscriptView) -> None:
        """The next window's view."""
        for e in view.undirected:
            self._keep(undirected_ambiguity(e), 0)
        if view.unanswerable:
            self.first = self.first or view.unanswerable[0]
            self.unanswerable += len(view.unanswerable)
        for a in view.transmission_ambiguities():
            self._keep(a, 2)

    def _keep(self, a: Ambiguity, group: int) -> None:
        self.count += 1
        self.seq += 1
        self.kept.append((a.at, group, self.seq, a))
        if len(self.kept) > 4 * self.shown:
            self.kept.sort(key=_PLACE)
            del self.kept[self.shown :]

    def found(self) -> tuple[int, list[str]]:
        """How many ambiguities the whole view has, and the first few as its notes quote
        them."""
        items = list(self.kept)
        if self.first is not None:
            one = unanswerable_ambiguity([self.first], self.unanswerable)
            items.append((one.at, 1, 0, one))
        items.sort(key=_PLACE)
        count = self.count + (1 if self.first is not None else 0)
        return count, [str(k[3]) for k in items[: self.shown]]


def _PLACE(k: tuple[float, int, int, Ambiguity]) -> tuple[float, int, int]:  # noqa: N802
    return k[:3]


class Qualities:
    """Each sensor's decode-quality note (by the first character of its exchanges' text),
    and all the sensors' together, from the windows' records in order: each window's
    characters' bit-rate errors its share of the decode's, in order."""

    def __init__(self, decoded: object) -> None:
        self.decoded = decoded
        self.broken = problems_by_character(decoded)
        self.taken = 0  # the decode's characters in the windows before
        self.by: dict[str, Quality] = {}
        self.all = Quality()

    def add(self, window: list[Event], exchanges: list[Exchange]) -> None:
        """The next window's events and its records' exchanges."""
        count = sum(1 for e in window if e.kind is EventKind.CHAR)
        part = self.decoded.baud_error_pct[self.taken : self.taken + count]  # type: ignore[attr-defined]
        rates = CharRates.of_rates(part, window)
        self.taken += count
        for x in exchanges:
            chars = sensor_characters([x])
            self.by.setdefault(x.text[:1], Quality()).add(chars, rates, self.broken)
            self.all.add(chars, rates, self.broken)


def count_typecode(most: int) -> str:
    """The ``array`` typecode for the bus pass's counts and indices, none above ``most`` (the
    recording's events: no window, window index or transmission count is more): 4 bytes,
    half what ``q`` took (an hour's windows, ~15,000, hold four such numbers each), 8 only
    past 2**32 - 1."""
    return "I" if most < 2**32 else "q"


class Sides:
    """Each event's inferred side as the bus pass cuts the windows (see the module's
    docstring): a :class:`~conformance.event_store.Column` begun at the first window whose
    sides were inferred (zeros for the events before it, whose sides were given), appended
    to a :data:`~conformance.event_store.BLOCK` at a time (a window's few bytes each one
    call of the column's cost 0.1 s of an hour's bus pass)."""

    def __init__(self) -> None:
        self.column: Column | None = None
        self.pending = bytearray()

    def add(self, before: int, sides: bytearray | None, count: int) -> None:
        """The next window's ``count`` events' sides (None: given), ``before`` events
        before it."""
        if sides is not None and self.column is None:
            self.column = Column("B")
            for at in range(0, before, CHUNK):  # a chunk's zeros at a time
                self.column.extend(bytes(min(CHUNK, before - at)))
        if self.column is not None:
            self.pending += sides if sides is not None else bytes(count)
            if len(self.pending) >= BLOCK:
                self._flush(self.pending)
                self.pending = bytearray()

    def _flush(self, data: bytes | bytearray) -> None:
        assert self.column is not None
        for at in range(0, len(data), CHUNK):
            self.column.extend(data[at : at + CHUNK])

    def done(self) -> Column | None:
        """The column (None: every side was given), all appended."""
        if self.column is not None and self.pending:
            self._flush(self.pending)
            self.pending = bytearray()
        return self.column


@dataclass
class BusWindows:
    """The bus pass over a loaded recording (see the module's docstring)."""

    events: Sequence[Event]  # the plain events in the order the windows cut them
    bounds: array  # window i is events[bounds[i]:bounds[i + 1]]
    #: each event's inferred side where its window's were inferred (None: the origins gave
    #: every side; else 0 for the events of a window whose sides were given)
    codes: Column | None
    sided: bytearray  # per window: 1 where the cut inferred its sides (``codes`` hold them)
    windows_of: dict[str, array]  # a text's first character -> the windows holding it
    sensors: list[BusSensor]
    ambiguities: tuple[int, list[str]]
    kinds: frozenset[Kind]  # the kinds of the commands the recorder sent (no_traffic's)
    qualities: dict[str, str | None] = field(default_factory=dict)
    all_quality: str | None = None
    #: how many of the whole view's transmissions come before each window (and after the
    #: last), all of them and those with characters (:meth:`transmissions`)
    before: array = field(default_factory=lambda: array("q", [0]))
    chars_before: array = field(default_factory=lambda: array("q", [0]))

    def transmissions(self) -> WindowedTransmissions:
        """The whole view's transmissions, read from the windows as they are asked for
        (the reports' search of the whole run: :func:`~conformance.view.runs.whole_cut`)."""
        return WindowedTransmissions(self.view, self.before, self.chars_before)

    def __len__(self) -> int:
        return len(self.bounds) - 1

    def view(self, i: int) -> TranscriptView:
        """Window ``i``'s view, read again as the cut read it."""
        return self.placed(i)[1]

    def placed(self, i: int) -> tuple[Positions | None, TranscriptView]:
        """Window ``i``'s view, read again as the cut read it, and where its events are in
        the store (None where the events are not a compact store's: no positions to keep)."""
        lo, hi = self.bounds[i], self.bounds[i + 1]
        sides = self.codes.read(lo, hi) if self.codes is not None and self.sided[i] else None
        window = list(self.events[lo:hi])
        view = window_view(window, sides)  # type: ignore[arg-type]
        if not isinstance(self.events, CompactEvents):
            return None, view
        return Positions(self.events, lo, window), view

    def read(self, address: str | None, more: Callable[[], bool]) -> Iterator[TranscriptView]:
        """The views of the windows holding a transmission whose text begins with
        ``address`` (every window for None), in order, and of each window after one while
        ``more()`` says the next traffic, whoever it is to, is still wanted."""
        return map(self.view, self.indices(address, more))

    def read_placed(
        self, address: str | None, more: Callable[[], bool]
    ) -> Iterator[tuple[Positions | None, TranscriptView]]:
        """:meth:`read`'s views, each with where its events are (:meth:`placed`)."""
        return map(self.placed, self.indices(address, more))

    def indices(self, address: str | None, more: Callable[[], bool]) -> Iterator[int]:
        """The windows :meth:`read` reads, in order."""
        if address is None:
            yield from range(len(self))
            return
        mine = self.windows_of.get(address, array("I"))
        i = j = 0
        while i < len(self):
            if j < len(mine) and mine[j] == i:
                j += 1
            elif not more():
                if j >= len(mine):
                    return
                i = mine[j]
                continue
            yield i
            i += 1


def bus_windows(link: RecordingLink) -> BusWindows:
    """The bus pass over ``link``'s recording, made once per loaded recording (the sensor
    runs, the recorder's and the check that the recording holds SDI-12 traffic read it)."""
    transcript = link.transcript

    def read() -> BusWindows:
        bus = _read_bus(link)
        # the reports' search of the whole run reads these windows, not a whole view
        transcript.__dict__["_whole_transmissions"] = (len(transcript), bus.transmissions)
        return bus

    return memo(link, "_bus_windows", len(transcript.events), read)


def _read_bus(link: RecordingLink) -> BusWindows:
    events = ordered_plain(link.transcript.events)
    u = link.uncertainty
    code = count_typecode(len(events))
    bounds, codes, sided = array(code, [0]), Sides(), bytearray()
    before, chars_before = array(code, [0]), array(code, [0])
    windows_of: dict[str, array] = {}
    sensors, ambiguities, carried = SensorsOn(), Ambiguities(AMBIGUITIES_SHOWN), {}
    kinds: set[Kind] = set()
    qualities = Qualities(link.decoded) if link.decoded is not None else None
    for window, sides in stream_window_sides(iter(events), uncertainty=u):
        i = len(bounds) - 1
        codes.add(bounds[-1], sides, len(window))
        bounds.append(bounds[-1] + len(window))
        sided.append(sides is not None)
        view = window_view(window, sides)
        before.append(before[-1] + len(view.transmissions))
        chars_before.append(chars_before[-1] + sum(1 for t in view.transmissions if t.chars))
        for first in {t.text[:1] for t in view.transmissions}:
            windows_of.setdefault(first, array(code)).append(i)
        kinds.update(t.command.kind for t in view.transmissions if t.command is not None)
        exchanges = rebuild_records(view, uncertainty=u, carried=carried).exchanges
        sensors.add(exchanges)
        ambiguities.add(view)
        if qualities is not None:
            qualities.add(window, exchanges)
    if bounds[-1] != len(events):
        raise AssertionError("the windows do not hold the recording's events one for one")
    found = BusWindows(
        events, bounds, codes.done(), sided, windows_of, sensors.sensors(), ambiguities.found(),
        frozenset(kinds), before=before, chars_before=chars_before,
    )  # fmt: skip
    if qualities is not None:
        baud = link.decoded.baud
        found.qualities = {a: q.note(baud, f"sensor {a!r}") for a, q in qualities.by.items()}
        found.all_quality = qualities.all.note(baud, "the sensor(s)")
    return found


@dataclass
class SensorRecords:
    """What a sensor's run reads (see the module's docstring): its exchanges and
    measurements (``aborted_by`` set) and its replies' timing and framing findings
    (R-7.0-09/-10, R-7.0-12 with R-7.0-01, R-4.1-01, R-4.1-02/-4.2-02/-4.2-03/-4.3-01)."""

    #: held as rows, each made again when read (:mod:`.held_exchanges`)
    exchanges: Sequence[Exchange]
    #: held as rows once decided, each made again when read (:mod:`.held_measurements`)
    measurements: Sequence[Measurement]
    response_start: list[Finding]
    gaps: list[Finding]
    bit_rate: Finding
    framing: list[Finding]


def sensor_records(link: RecordingLink, bus: BusWindows, address: str | None) -> SensorRecords:
    """The sensor pass for ``address`` (None: every sensor together)."""
    u, stamps = link.uncertainty, stamp_uncertainty_of(link)
    # the tool's host stalls a run of this tool noted (a capture has none): the framing and
    # every record whose read one may have held up are read as the live run reads them
    stalls = noted_stalls(link.transcript.events)
    starts, gaps = ResponseStarts(stamps, stalls), ReplyGaps(stamps, stalls)
    rate, framing = ReplyBitRate(stamps), Framing(stamps, stalls=stalls)
    disturbed, carried = Disturbances(), {}
    events = link.transcript.events
    exchanges = HeldExchanges(events if isinstance(events, CompactEvents) else None)
    measurements = HeldMeasurements(exchanges)
    for positions, view in bus.read_placed(address, disturbed.waiting):
        rebuilt = rebuild_records(view, uncertainty=u, only=address, carried=carried)
        stalled_reads.mark_reads(rebuilt.exchanges, stalls)
        stalled_reads.mark_waits(rebuilt.measurements, stalls)
        disturbed.add(view, rebuilt.measurements)
        segs = [Segment.of(t) for t in view.transmissions if address in (None, t.text[:1])]
        for fold in (starts, gaps, rate, framing):
            fold.add(segs)
        if positions is not None:  # held for the run as positions, not objects
            store_records(positions, rebuilt.exchanges, rebuilt.measurements)
        exchanges.add(positions, rebuilt.exchanges, measured(rebuilt.measurements))
        measurements.add(rebuilt.measurements)
        measurements.settle({id(w.m) for w in disturbed.watched})
    disturbed.finish()
    measurements.settle(())
    return SensorRecords(
        exchanges, measurements, starts.findings(), gaps.findings(), rate.finding(),
        framing.findings(),
    )  # fmt: skip


def measured(measurements: Iterable[Measurement]) -> set[int]:
    """The ids of the exchanges ``measurements`` hold (each one's start and data): kept as the
    objects in a sensor's held exchanges, the very ones its measurements read, while those
    measurements are (:mod:`.held_measurements`)."""
    return {id(x) for m in measurements for x in (m.start, *m.data)}


def noted_stalls(events: Sequence[Event]) -> list[host_stall.Stall]:
    """:func:`~conformance.links.host_stall.stalls_since` the recording's start, asked of a
    compact store's fields first: a store holding no note holds no stall, and looking for
    one made each of its events (an hour's capture: 357,000, 0.12 s of CPU each sensor's
    run)."""
    if isinstance(events, CompactEvents) and not events.has_kind(EventKind.NOTE):
        return []
    return host_stall.stalls_since(events, 0)  # type: ignore[arg-type]


class Disturbances:
    """What the recorder did that keeps each measurement's wait and data from being the
    sensor's own doing (``Measurement.aborted_by``, see :func:`disturbance_of`), decided
    from the windows' views in order: a measurement's window holds it from its command to
    its last data command, but what decides it may come later (the traffic within ttt of
    its reply, the next transmission, for a concurrent one the next to its sensor), so a
    measurement not yet decided is watched over the next windows' transmissions and breaks,
    carried alone (:class:`_Watch`), the rest decided and let go."""

    def __init__(self) -> None:
        self.watched: list[_Watch] = []

    def waiting(self) -> bool:
        """Whether a measurement still waits on the next traffic to anyone (an aM!-type
        one: a concurrent one waits on its own sensor's, in that sensor's windows)."""
        return any(not w.concurrent for w in self.watched)

    def add(self, view: TranscriptView, measurements: list[Measurement]) -> None:
        """The next window's view and its records' measurements (of the sensor judged)."""
        for w in self.watched:
            w.feed(view)
        for m in measurements:
            w = _Watch(m)
            if not w.done:
                w.feed(view)
            self.watched.append(w)
        for w in self.watched:
            if w.done:
                w.m.aborted_by = w.why
        self.watched = [w for w in self.watched if not w.done]

    def finish(self) -> None:
        """The recording ended: every measurement still watched decided on what came."""
        for w in self.watched:
            w.end()
            w.m.aborted_by = w.why
        self.watched.clear()


def disturbance(m: Measurement, view: TranscriptView) -> str | None:
    """What the recorder did that keeps ``m``'s wait and data from being the sensor's own
    doing: a transmission or a break before the service request (or ttt) of an aM!-type
    measurement, or anything but its aD0!/aDB0! as the next transmission (after an aM!-type
    measurement the recorder talks to no one else, R-4.4.5-06). A concurrent measurement
    (C/CC/Cn/CCn/HA/HB) is disturbed only by a command to its own sensor before its aD0!
    (it aborts it, R-4.4.7.1-01, R-5.3-01): traffic to other sensors is what it is for, and
    a break does not abort it either (R-4.4.7-05, decision A4), so neither sets it aside.
    The rebuilt records follow its data the same way. None: undisturbed. ``view``: the
    whole recording's (one :class:`Disturbances` window, the same code); ``m`` is not
    changed."""
    w = _Watch(m)
    if not w.done:
        w.feed(view)
    if not w.done:
        w.end()
    return w.why


class _Watch:
    """One measurement's disturbance (:func:`disturbance`), decided as the transmissions and
    breaks after its reply come (in time order, as a view holds them): the first
    transmission within its service request's due time (aM!-type), else a break there, else
    what the first later transmission (for a concurrent measurement: to its own sensor)
    says."""

    def __init__(self, m: Measurement) -> None:
        self.m, self.done, self.why = m, False, None
        self.concurrent = m.command.kind in CONCURRENT_KINDS
        self.first: Transmission | None = None
        self.broke = False
        if m.reply_end is None or m.ttt is None:
            self._decide("no usable reply")
            return
        self.reply_end = m.reply_end
        self.sr = m.command.kind in SERVICE_REQUEST_KINDS and bool(m.ttt)
        self.due = (m.service_request_end or m.reply_end + m.ttt) if self.sr else 0.0
        self.breaks_past = self.sent_past = not self.sr  # past the due time (aM!-type)

    def _decide(self, why: str | None) -> None:
        self.why, self.done = why, True

    def feed(self, view: TranscriptView) -> None:
        """The next view's breaks and transmissions (this measurement's own view first)."""
        at = self.reply_end
        for b in view.breaks:
            if self.breaks_past:
                break
            if b.start >= self.due:
                self.breaks_past = True
            elif b.start >= at:
                self.broke = True
        for t in view.transmissions:
            if t.start < at:
                continue
            if not self.sent_past:
                if t.start < self.due:
                    self._decide(t.text)
                    return
                self.sent_past = True
            if self.first is None and (not self.concurrent or t.address == self.m.command.address):
                self.first = t
                break
        if self.sent_past and self.breaks_past and (self.broke or self.first is not None):
            self.end()

    def end(self) -> None:
        """Decided on what was fed (the recording may have ended)."""
        if self.broke:
            self._decide("break")  # a break aborts an aM!-type measurement (R-4.4.5-10)
            return
        first, m = self.first, self.m
        if first is None:
            self._decide("nothing more sent")
            return
        index = first.data_index
        if first.address != m.command.address or index is None or index[1] != 0:
            # the records follow a measurement's data only while nothing else comes between
            self._decide(first.text)
        elif not collected(m):
            self._decide("the recorder stopped asking for data while values were due")
        else:
            self._decide(None)


def collected(m: Measurement) -> bool:
    """Whether the recorder asked until the sensor had no more to give (every announced
    value in, an empty reply or packet, or the last index), as the tool recorder does: a
    recorder that stopped sooner leaves the count rules without their stimulus."""
    if not m.data or m.count is None:
        return False
    last = m.data[-1]
    if not last.answered:
        return True  # a silent data command: the sensor's doing, judged as such
    if m.binary:
        if m.binary_value_count >= m.count:
            return True
        return (
            len(last.reply_bytes) <= EMPTY_PACKET
            or last.command is None
            or (last.command.index is not None and last.command.index >= LAST_HV_INDEX)
        )
    if m.value_count >= m.count:
        return True
    text = validity.data_values_text(last.reply_text, m.command.returns_crc)
    index = last.command.index if last.command is not None else None
    limit = LAST_HV_INDEX if m.command.kind is Kind.HIGH_VOLUME_ASCII else LAST_INDEX
    return not split_values(text) or (index is not None and index >= limit)
