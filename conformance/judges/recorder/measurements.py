"""Measurement reconstruction: every measurement the recorder under test started with a
valid ``atttn``-type reply, the service request, and the data transmissions that followed."""

from __future__ import annotations

from dataclasses import dataclass

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
    """Every measurement the recorder started with a valid ``atttn``-type reply."""
    crc = crc_context(line)
    problems = [reply_problem(s, crc[i], uncertainty) for i, s in enumerate(line.transmissions)]
    taken: list[ObservedMeasurement] = []
    for i, s in enumerate(line.transmissions):
        cmd = s.command
        if cmd is None or not cmd.starts_measurement or problems[i] is not None:
            continue
        if _after_the_job(line, s):
            continue  # the recorder had ended its job: it never heard this reply
        body, _ = split_line(decode_7e1(s.reply))
        parsed = parse_measurement_reply_for(body, cmd)
        if parsed.ttt is None or parsed.count is None:
            continue
        ttt, count = parsed.ttt, parsed.count
        sr = service_request_end(s.after, cmd.address)
        data: list[tuple[Transmission, ReplyProblem | None]] = []
        others: list[Transmission] = []
        nxt: Transmission | None = None
        left = False  # the recorder turned to something else at this address
        for j in range(i + 1, len(line.transmissions)):
            t = line.transmissions[j]
            if t.part != s.part:
                break
            if t.address != cmd.address:
                others.append(t)
                continue
            tc = t.command
            if t.data_index is not None:
                data.append((t, problems[j]))
                continue
            if tc is not None and tc.kind in KEEPS_DATA and t.start >= _finished(s, ttt, sr):
                continue  # the data stay the sensor's to give (4.4.5, 4.4.7)
            if tc is not None and tc.starts_measurement:
                nxt = t
            left = True
            break
        if data:
            last = data[-1][0]
            others = [o for o in others if o.start < last.end]
        taken.append(
            ObservedMeasurement(
                i,
                s,
                cmd,
                ttt,
                count,
                s.reply[-1].end,
                sr,
                data,
                nxt,
                others,
                None if left else line.cut_parts.get(s.part),
            )
        )
    return taken


#: Commands that neither return data via D0 nor change the address: after a measurement has
#: finished, the sensor "must retain the measured data in memory until it receives another
#: M, C or V command, or another command that returns data via the D0 command" (4.4.5,
#: 4.4.7), so a recorder that sends one of these (esp-sdi-12's device API sends ``a!`` the
#: first time it meets an address, docs/kit.md) is still in the measurement. Before it has
#: finished, a valid command to the sensor aborts a concurrent one (4.4.7.1).
KEEPS_DATA = frozenset({Kind.ACKNOWLEDGE, Kind.IDENTIFY, Kind.IDENTIFY_MEASUREMENT, Kind.METADATA})


def _finished(s: Transmission, ttt: int, sr: float | None) -> float:
    """When the measurement ``s`` started was over: its service request, else ttt after its
    reply (the sensor's own promise of when its data are ready)."""
    ready = s.reply[-1].end + ttt
    return ready if sr is None else min(sr, ready)


def _after_the_job(line: TranscriptView, s: Transmission) -> bool:
    """Whether ``s``'s reply began after the recorder ended its job (``ended_parts``): a
    measurement it never heard announced, so it owed none of its values (the retry rules
    judge a command given up on; R-4.4.8-05 would blame a collection never begun)."""
    end = line.ended_parts.get(s.part)
    return end is not None and bool(s.reply) and s.reply[0].start >= end


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
