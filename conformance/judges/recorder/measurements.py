"""Measurement reconstruction: every measurement the recorder under test started with a
valid ``atttn``-type reply, the service request, and the data transmissions that followed."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from ...protocol.binary import DataType, parse_binary_packet
from ...protocol.commands import Command, Kind
from ...protocol.responses import parse_measurement_reply_for, service_request, split_line
from ...transcript import Event, decode_7e1, decode_8n1, text_end
from ...view.segments import TranscriptView, Transmission
from ..reply_validity import ReplyProblem
from .replies import crc_context, data_values, reply_problem


@dataclass
class ObservedMeasurement:
    """A measurement the recorder started and what it did until it was done with it."""

    index: int  # position of the starting transmission in line.transmissions
    start: Transmission
    command: Command
    ttt: int
    count: int
    reply_end: float
    service_request_end: float | None
    data: list[tuple[Transmission, ReplyProblem | None]]  # data transmissions, with their problems
    next_start: Transmission | None  # the next measurement command to the same sensor, if any
    others: list[Transmission]  # transmissions to other sensors before the data were all in
    #: the line time at which the tool cut the job at its budget while the recorder was still
    #: in this measurement (nothing it sent after the measurement ended it): what it had not
    #: done by then is unobserved, not refused (None: the recorder itself moved on or ended)
    cut_at: float | None = None

    @property
    def kind(self) -> Kind:
        return self.command.kind

    def values(self) -> list[str]:
        """Values of the valid data replies, each index counted once."""
        return [text for text, _ in self.sent_values()]

    def sent_values(self) -> list[tuple[str, DataType | None]]:
        """:meth:`values` with the binary data type of each (None: an ASCII value), so a
        logged value can be compared with an HB value at the precision of its type."""
        seen: set[int] = set()
        values: list[tuple[str, DataType | None]] = []
        for sent, problem in self.data:
            d = sent.data_index
            if problem is not None or d is None or d[1] in seen:
                continue
            seen.add(d[1])
            if d[0]:
                packet = parse_binary_packet(decode_8n1(sent.reply))
                values += [(repr(v), DataType(packet.dtype)) for v in packet.values]
            else:
                values += [(v, None) for v in data_values(sent, self.command)]
        return values

    def unread_indices(self) -> list[int]:
        """Data indices whose every reply was invalid: values the recorder never validly
        received (the retry rules judge those, R-7.2-05 and R-4.4.12-07)."""
        valid = {d[1] for s, p in self.data if p is None and (d := s.data_index) is not None}
        tried = {d[1] for s, _ in self.data if (d := s.data_index) is not None}
        return sorted(tried - valid)

    @property
    def first_data(self) -> Transmission | None:
        return self.data[0][0] if self.data else None


def service_request_end(events: list[Event], address: str) -> float | None:
    """End of the first ``a<CR><LF>`` with good parity among ``events`` (R-4.4.6-01)."""
    return text_end(events, service_request(address))


def observed_measurements(line: TranscriptView, uncertainty: float) -> list[ObservedMeasurement]:
    """Every measurement the recorder started with a valid ``atttn``-type reply (one
    :meth:`ObservedMeasurements.add` of the whole view: the windowed judge's code path)."""
    taken = ObservedMeasurements(uncertainty)
    taken.add(line)
    return taken.measurements()


@dataclass
class _Following:
    """A measurement whose transmissions are still being followed: its data, the
    transmissions to other sensors since it began and the next measurement command to its
    sensor so far, until a transmission of another part or a non-data one to its sensor
    ends it (or the recording does)."""

    index: int
    start: Transmission
    command: Command
    ttt: int
    count: int
    service_request_end: float | None
    data: list[tuple[Transmission, ReplyProblem | None]] = field(default_factory=list)
    others: list[Transmission] = field(default_factory=list)
    next_start: Transmission | None = None

    def follow(self, t: Transmission, problem: ReplyProblem | None) -> bool | None:
        """Take ``t``, the next transmission on the line: None while the measurement goes
        on, else whether the recorder turned to something else at its address (True) or the
        part ended (False)."""
        if t.part != self.start.part:
            return False
        if t.address != self.command.address:
            self.others.append(t)
            return None
        if t.data_index is not None:
            self.data.append((t, problem))
            return None
        tc = t.command
        if tc is not None and tc.kind in KEEPS_DATA and t.start >= self.finished():
            return None  # the data stay the sensor's to give (4.4.5, 4.4.7)
        if tc is not None and tc.starts_measurement:
            self.next_start = t
        return True

    def finished(self) -> float:
        """When the measurement was over: its service request, else ttt after its reply
        (the sensor's own promise of when its data are ready)."""
        ready = self.start.reply[-1].end + self.ttt
        sr = self.service_request_end
        return ready if sr is None else min(sr, ready)

    def taken(self, cut_at: float | None) -> ObservedMeasurement:
        """What was followed, as the judges read it (``cut_at``: see
        :attr:`ObservedMeasurement.cut_at`)."""
        others = self.others
        if self.data:
            last = self.data[-1][0]
            others = [o for o in others if o.start < last.end]
        s = self.start
        return ObservedMeasurement(
            self.index, s, self.command, self.ttt, self.count, s.reply[-1].end,
            self.service_request_end, self.data, self.next_start, others, cut_at,
        )  # fmt: skip


class ObservedMeasurements:
    """:func:`observed_measurements` of a recording given a window at a time (issue 22's
    windowed judge): :meth:`add` each window's view in order, then :meth:`measurements`.
    A measurement looks past its window (its sensor's next command may come windows later,
    and the transmissions to other sensors until then are its ``others``), so each one is
    followed over the windows after it until something ends it; carried besides: each
    address's CRC expectation (:func:`~.replies.crc_context`), the transmissions of the
    windows before (each measurement's ``index`` is its place in the whole recording) and
    the parts the tool cut or ended (:attr:`TranscriptView.cut_parts`, ``ended_parts``:
    from a run's notes, which a window of a capture has none of).

    A fold that judges the measurements as they come takes :meth:`finished` after each
    :meth:`add` (each measurement once it is over, in the order begun: one over waits for
    those begun before it still followed) and :meth:`rest` at the end: what it hands out
    it forgets, so what it holds is the measurements still followed and those over behind
    them (:attr:`held`), not the recording's (issue 22, memory27: a measuring bus's
    measurements held every event of the recording, ~0.6 MB a minute)."""

    def __init__(self, uncertainty: float) -> None:
        self.uncertainty = uncertainty
        self._crc: dict[str, bool] = {}
        self._before = 0  # transmissions in the windows before
        self._cut_parts: dict[int, float] = {}
        self._ended_parts: dict[int, float] = {}
        #: those not yet handed out, in the order begun (:meth:`finished`)
        self._taken: deque[ObservedMeasurement | _Following] = deque()
        self._gone = 0  # measurements handed out (their places in the order begun)
        self._following: list[int] = []  # where in the order begun those still followed are

    @property
    def held(self) -> int:
        """The measurements held: those still followed and those over behind them."""
        return len(self._taken)

    def add(self, line: TranscriptView) -> None:
        """Take the next window's view."""
        self._cut_parts.update(line.cut_parts)
        self._ended_parts.update(line.ended_parts)
        crc = crc_context(line, self._crc)
        taken = self._taken
        for i, s in enumerate(line.transmissions):
            problem = reply_problem(s, crc[i], self.uncertainty)
            still: list[int] = []
            gone = self._gone
            for k in self._following:
                m = taken[k - gone]
                assert isinstance(m, _Following)
                left = m.follow(s, problem)
                if left is None:
                    still.append(k)
                else:
                    cut = None if left else self._cut_parts.get(m.start.part)
                    taken[k - gone] = m.taken(cut)
            self._following = still
            begun = self._begun(s, problem, self._before + i)
            if begun is not None:
                self._following.append(gone + len(taken))
                taken.append(begun)
        self._before += len(line.transmissions)

    def finished(self) -> list[ObservedMeasurement]:
        """The measurements over since the last call, in the order begun, up to the first
        still followed (those over after it wait for it), each handed out once and
        forgotten."""
        taken = self._taken
        out: list[ObservedMeasurement] = []
        while taken and isinstance(taken[0], ObservedMeasurement):
            out.append(taken.popleft())
        self._gone += len(out)
        return out

    def rest(self) -> list[ObservedMeasurement]:
        """Every measurement not handed out, the recording over (those still followed end
        with it, cut where the tool cut their part), handed out and forgotten."""
        out = self.measurements()
        self._gone += len(self._taken)
        self._taken.clear()
        self._following = []
        return out

    def _begun(
        self, s: Transmission, problem: ReplyProblem | None, index: int
    ) -> _Following | None:
        """The measurement ``s`` started (None: it started none the recorder heard)."""
        cmd = s.command
        if cmd is None or not cmd.starts_measurement or problem is not None:
            return None
        end = self._ended_parts.get(s.part)
        if end is not None and s.reply and s.reply[0].start >= end:
            # the recorder had ended its job (ended_parts): it never heard this reply, so it
            # owed none of its values (the retry rules judge a command given up on;
            # R-4.4.8-05 would blame a collection never begun)
            return None
        body, _ = split_line(decode_7e1(s.reply))
        parsed = parse_measurement_reply_for(body, cmd)
        if parsed.ttt is None or parsed.count is None:
            return None
        sr = service_request_end(s.after, cmd.address)
        return _Following(index, s, cmd, parsed.ttt, parsed.count, sr)

    def measurements(self) -> list[ObservedMeasurement]:
        """Every measurement of the recording so far not handed out (:meth:`finished`), in
        the order begun: those still followed end with it (cut where the tool cut their
        part)."""
        return [
            m if isinstance(m, ObservedMeasurement) else m.taken(self._cut_parts.get(m.start.part))
            for m in self._taken
        ]


#: Commands that neither return data via D0 nor change the address: after a measurement has
#: finished, the sensor "must retain the measured data in memory until it receives another
#: M, C or V command, or another command that returns data via the D0 command" (4.4.5,
#: 4.4.7), so a recorder that sends one of these (esp-sdi-12's device API sends ``a!`` the
#: first time it meets an address, docs/kit.md) is still in the measurement. Before it has
#: finished, a valid command to the sensor aborts a concurrent one (4.4.7.1).
KEEPS_DATA = frozenset({Kind.ACKNOWLEDGE, Kind.IDENTIFY, Kind.IDENTIFY_MEASUREMENT, Kind.METADATA})


def collection_end(m: ObservedMeasurement) -> tuple[Transmission | None, ReplyProblem | None, bool]:
    """The last data transmission, its problem, and whether its valid reply was empty."""
    if not m.data:
        return None, None, False
    sent, problem = m.data[-1]
    if problem is not None:
        return sent, problem, False
    return sent, None, _empty(m, sent)


def read_past_empty(m: ObservedMeasurement) -> Transmission | None:
    """The first data transmission whose valid reply was empty and after which the recorder
    asked for more data (D1 after an empty D0): the collection's end says nothing of it when
    a later one failed (ESP32-SDI12 went on to aD10!, unanswered, docs/kit.md)."""
    for sent, problem in m.data[:-1]:
        if problem is None and _empty(m, sent):
            return sent
    return None


def _empty(m: ObservedMeasurement, sent: Transmission) -> bool:
    if sent.binary:
        return not parse_binary_packet(decode_8n1(sent.reply)).values
    return not data_values(sent, m.command)
