"""The tool recorder's records (:mod:`conformance.tool_recorder.records`) rebuilt from a view.

The sensor judges read :class:`~conformance.tool_recorder.records.Exchange` and
:class:`~conformance.tool_recorder.records.Measurement` records, which the tool recorder
writes as it drives the bus. To judge the sensor rules on a recording no tool drove (a
capture, a saved transcript), the same records are rebuilt here from the wire alone: each
transmission becomes an attempt; consecutive transmissions of one command whose reply was
not accepted are its retries (a break starts a new sequence); a measurement command with an
``atttn`` reply, the sensor's characters while it waited (service request) and the
``aD0!``.. ``aDn!`` that followed become a measurement (for a concurrent measurement, the
``aD0!``.. of its address that followed, whatever was said to other sensors between).

Whether an attempt's reply was accepted is the tool recorder's own decision
(:mod:`conformance.tool_recorder.validity`), as in the records it writes live: these are its
records, read back, not a judge's opinion. What the wire cannot tell is left out and said so:
``Attempt.end`` (when the recorder stopped listening) is taken as the end of the reply or of
the first-character timeout.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from operator import attrgetter, sub

from ..protocol.binary import packet_length
from ..protocol.commands import CONCURRENT_KINDS, SERVICE_REQUEST_KINDS, Command, Kind
from ..protocol.framing import ETX, STX
from ..protocol.responses import parse_measurement_reply_for, service_request, split_line
from ..protocol.timing import CHAR_TIME, TOLERANCE
from ..tool_recorder import validity
from ..tool_recorder.engine import reads_on, take_values
from ..tool_recorder.policy import Policy
from ..tool_recorder.records import CONTENTION, IDLE, NO_REPLY, OK, Attempt, Exchange, Measurement
from ..transcript import Event, decode_8n1, text_end
from .segments import TranscriptView, Transmission

_START = attrgetter("start")
#: the kinds every transmission is asked about, as module constants: a member read off the enum goes
#: through its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_DATA, _BINARY_DATA = Kind.DATA, Kind.BINARY_DATA
_END = attrgetter("end")


@dataclass
class Rebuilt:
    """The exchanges in wire order (measurement starts and data included) and the
    measurements they form; ``open``: those of them whose data the exchanges ran out on
    (the next exchange could still be their data: a window of a recording ended there)."""

    exchanges: list[Exchange]
    measurements: list[Measurement]
    open: list[Measurement] = field(default_factory=list)


def rebuild_records(
    view: TranscriptView,
    policy: Policy | None = None,
    *,
    uncertainty: float = 0.0,
    only: str | None = None,
    carried: dict[str, bool] | None = None,
) -> Rebuilt:
    """Exchanges and measurements from ``view``, as the tool recorder would have recorded
    them with ``policy`` (its reply window and idle rule decide where a reply ends).

    ``only``: the records of the sensor at that address alone, equal to the whole run's
    records of that address (exchanges by their text's first character, measurements by
    their command's address), without the other sensors' ever being made: a passive
    judgement of a bus judges one sensor at a time, and holding every sensor's records at
    the first one's run held an hour's capture's 15 MB at its peak. What another sensor's
    transmission changes for this one's is only that it came between (it ends an aM!-type
    measurement's data, :func:`_measurements`) and that it is no retry of this one's last
    exchange; the CRC expected of a data reply is its own address's.

    ``carried``: whether each address's last measurement asked for a CRC, from before
    ``view`` (a window of a longer recording, :mod:`.windows`): a data reply read long after
    its measurement is judged by it. Updated in place with ``view``'s, for the next window."""
    return records_of(
        view.transmissions, policy, uncertainty=uncertainty, only=only, carried=carried
    )


def records_of(
    transmissions: list[Transmission],
    policy: Policy | None = None,
    *,
    uncertainty: float = 0.0,
    only: str | None = None,
    carried: dict[str, bool] | None = None,
) -> Rebuilt:
    """:func:`rebuild_records` of a view's ``transmissions``, all it reads of the view: a
    live session hands the transmissions of its one cut (:mod:`.live_cut`)."""
    policy = policy or Policy()
    source: dict[int, Transmission] = {}  # id(attempt) -> the transmission it was
    exchanges = list(_exchanges(transmissions, policy, uncertainty, only, source, carried))
    open_: list[Measurement] = []
    measurements = _measurements(exchanges, source, policy, open_)
    return Rebuilt([x for x in exchanges if x is not None], measurements, open_)


def rebuilt_exchanges(
    view: TranscriptView, policy: Policy | None = None, *, uncertainty: float = 0.0
) -> Iterator[Exchange]:
    """:func:`rebuild_records`'s exchanges, each given once complete (its retries in) and
    held by nobody else: what reads every sensor's exchanges once (the sensors on a bus,
    their characters' decode quality) then holds one exchange at a time, not an hour's
    capture's 15 MB of them."""
    found = _exchanges(view.transmissions, policy or Policy(), uncertainty, None, {})
    return (x for x in found if x is not None)


def _exchanges(
    transmissions: list[Transmission],
    policy: Policy,
    uncertainty: float,
    only: str | None,
    source: dict[int, Transmission],
    crc_pending: dict[str, bool] | None = None,
) -> Iterator[Exchange | None]:
    """The exchanges of ``transmissions`` in wire order, each once its last attempt is in (of the
    sensor at ``only``, with a None where other sensors' exchanges came between); fills
    ``source`` (id of each attempt -> its transmission) and ``crc_pending`` (address ->
    whether its last measurement asked for a CRC; what came before ``view`` if given)."""
    if crc_pending is None:
        crc_pending = {}
    last: Exchange | None = None  # the last exchange, None when it is another sensor's
    begun = False
    for t in transmissions:
        if only is not None and t.text[:1] != only:
            if last is not None or not begun:
                if last is not None:
                    yield last
                yield None
            last, begun = None, True
            continue
        command = t.command
        binary = command is not None and command.kind is _BINARY_DATA
        crc = crc_pending.get(t.address) if binary or _is_data(command) else None
        attempt = _attempt(t, command, binary, crc, policy, uncertainty)
        source[id(attempt)] = t
        if last is not None and last.text == t.text and not last.ok and command is not None:
            # what the sensor sent after the try before stopped being listened to, before
            # this retry: queued before it went out, a stray of this attempt, as the engine
            # records it (a reply 290 ms late between two retry sequences, docs/kit.md's
            # twenty-first round, read as no reply at all by exchanges.late_reply)
            before = source[id(last.last)].heard
            attempt.stray_events[:0] = [e for e in before if e.start >= last.last.end]
            retries = [a for a in last.attempts if a.sequence == last.last.sequence]
            if t.break_event is None:
                attempt.sequence, attempt.retry = last.last.sequence, len(retries)
            else:
                attempt.sequence = last.last.sequence + 1
            last.attempts.append(attempt)
        else:
            if last is not None:
                yield last
            last, begun = Exchange(command, t.text, [attempt], binary=binary), True
        if command is not None and command.starts_measurement and (attempt.ok or policy.salvage):
            crc_pending[command.address] = command.returns_crc
    if last is not None:
        yield last


def _is_data(command: Command | None) -> bool:
    return command is not None and command.kind is _DATA


def _attempt(
    t: Transmission,
    command: Command | None,
    binary: bool,
    crc: bool | None,
    policy: Policy,
    uncertainty: float,
) -> Attempt:
    stray = list(t.contention)
    end = t.end
    # the first character heard after the command ended: all the framing asks of them
    first = next((e for e in t.heard if e.start >= end), None)
    reply = _framed(t, first, policy)
    if stray:
        reason = f"{CONTENTION} ({len(stray)} characters during the command)"
    elif not reply:
        reason = NO_REPLY
    elif not _complete(t, reply):
        reason = IDLE
    elif binary:
        why = validity.check_packet(reply, address=t.address, command_end=t.end)
        reason = OK if why is None else f"invalid: {why}"
    else:
        why = validity.check_ascii(
            command,
            reply,
            address=t.address,
            command_end=t.end,
            gap_limit=CHAR_TIME + TOLERANCE + uncertainty,
            crc_expected=crc,
            multiline=len(reply) > 1 and reply[1].char7 == STX,
        )
        reason = OK if why is None else f"invalid: {why}"
    end = reply[-1].end if reply else t.end + policy.first_char_timeout
    return Attempt(t.break_event, list(t.chars), reply, reason, end, stray_events=stray)


def _framed(t: Transmission, first: Event | None, policy: Policy) -> list[Event]:
    """The reply as the tool recorder frames it: the first character heard after the
    command (``first``) within its first-character timeout, then the protocol's framing,
    cut where the line idled."""
    if first is None or first.start - t.end > policy.first_char_timeout:
        return []
    framed = t.reply
    if len(framed) < 2 or max(map(sub, map(_START, framed[1:]), map(_END, framed))) <= (
        policy.reply_idle
    ):
        return framed  # no gap longer than the idle: nothing cut (one C pass over the gaps)
    for i in range(1, len(framed)):
        multiline_gap = framed[i - 1].char7 == 0x0A
        if not multiline_gap and framed[i].start - framed[i - 1].end > policy.reply_idle:
            return framed[:i]
    return framed


def _complete(t: Transmission, reply: list[Event]) -> bool:
    if t.binary:
        length = packet_length(decode_8n1(reply))
        return length is not None and len(reply) >= length
    return validity.ends_line(reply) or reply[-1].char7 == ETX


def _measurements(
    exchanges: list[Exchange | None],
    source: dict[int, Transmission],
    policy: Policy,
    open_: list[Measurement] | None = None,
) -> list[Measurement]:
    """The measurements the exchanges start, each with its data; a None among ``exchanges``
    stands for other sensors' exchanges (:func:`rebuild_records`'s ``only``). ``open_``:
    given the measurements whose data nothing ended but the end of ``exchanges``."""
    found: list[Measurement] = []
    for i, ex in enumerate(exchanges):
        command = ex.command if ex is not None else None
        if ex is None or command is None or not command.starts_measurement:
            continue
        m = Measurement(command, ex)
        found.append(m)
        if not (ex.ok or policy.salvage) or not ex.reply_events:
            continue
        body, _ = split_line(ex.reply_text)
        parsed = parse_measurement_reply_for(body, command)
        if parsed.ttt is None or parsed.count is None or not ex.reply_text.endswith("\r\n"):
            continue
        m.ttt, m.count = parsed.ttt, parsed.count
        m.reply_end = ex.reply_events[-1].end
        if m.ttt > 0:
            m.waited_events = _waited(m, source[id(ex.last)], policy)
            m.service_request_end = text_end(m.waited_events, service_request(command.address))
        probed_past_empty = False
        for later in _following(exchanges[i + 1 :], m):
            if later is None or not _collects(later, m) or m.value_count >= m.count:
                break
            m.data.append(later)
            if not (later.ok or (policy.salvage and later.answered)):
                break
            if not take_values(m, later, m.command.returns_crc) and not reads_on(m, policy):
                # an observer looks one index past an empty reply, once (as the engine does)
                if not policy.salvage or probed_past_empty or m.binary:
                    break
                probed_past_empty = True
        else:  # the exchanges ran out first: a later exchange could still be its data
            if open_ is not None and m.value_count < m.count:
                open_.append(m)
    return found


def _waited(m: Measurement, t: Transmission, policy: Policy) -> list[Event]:
    """What the tool recorder heard while it waited for the data: the sensor's characters
    after the reply, up to the service request for M/V (it stops listening there), else until
    ttt (and its margin) ran out."""
    assert m.reply_end is not None and m.ttt is not None
    reply = {id(e) for e in m.start.reply_events}
    after = [e for e in t.heard if e.start >= t.end and id(e) not in reply]
    if m.command.kind in SERVICE_REQUEST_KINDS:
        deadline = m.reply_end + m.ttt + max(policy.late_sr_grace, policy.ttt_margin)
        waited: list[Event] = []
        for e in after:
            if e.end > deadline:
                break
            waited.append(e)
            if text_end(waited, service_request(m.command.address)) is not None:
                break
        return waited
    deadline = m.reply_end + m.ttt + policy.ttt_margin
    return [e for e in after if e.end <= deadline]


def _following(later: list[Exchange | None], m: Measurement) -> Iterator[Exchange | None]:
    """The exchanges that may carry ``m``'s data, in wire order. A concurrent measurement
    (C/CC/Cn/CCn/HA/HB) runs while the recorder talks to other sensors (R-4.4.7-05, R-5.3-01):
    that is what it is for, so only the exchanges to its own address follow it (the first
    that is not its next data command ends it, as a command to it aborts it, R-4.4.7.1-01).
    After an aM!-type measurement the recorder talks to no one else (R-4.4.5-06): the very
    next exchange is its data or the end of it (a None, other sensors' exchanges, ends it;
    a concurrent one passes over it)."""
    concurrent = m.command.kind in CONCURRENT_KINDS
    # lazily: the caller stops at the first exchange that is not the next data command
    if not concurrent:
        return iter(later)
    return (x for x in later if x is not None and x.text[:1] == m.command.address)


def _collects(ex: Exchange | None, m: Measurement) -> bool:
    """``ex`` is the next data command of ``m``: same address, the next index (None, other
    sensors' exchanges, never is)."""
    cmd = ex.command if ex is not None else None
    want = Kind.BINARY_DATA if m.binary else Kind.DATA
    return (
        cmd is not None
        and cmd.kind is want
        and cmd.address == m.command.address
        and cmd.index == len(m.data)
    )


__all__ = ["Rebuilt", "rebuild_records", "rebuilt_exchanges", "records_of"]
