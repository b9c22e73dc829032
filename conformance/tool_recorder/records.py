"""What the tool recorder hands back: plain records of what it sent and what came back.

The engine never judges. It keeps every attempt (break, command characters, reply characters,
and why the attempt ended) so that judges can decide timing, format and retry questions from
the records alone, and so that a misbehaving sensor leaves evidence instead of an exception.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..protocol.commands import Command, Kind
from ..protocol.values import split_values
from ..transcript import Event, decode_7e1, decode_8n1
from .validity import data_values_text, packet_value_count, salvaged_values_text

if TYPE_CHECKING:
    from ..links.host_stall import Stall

# Reasons an attempt ended. "invalid: <why>" carries the engine's own (loose) reason.
#: the kinds records are asked about, as module constants: a member read off the enum goes through
#: its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_DATA_KINDS = (Kind.DATA, Kind.BINARY_DATA)
_HIGH_VOLUME_BINARY = Kind.HIGH_VOLUME_BINARY

OK = "ok"
NO_REPLY = "no reply"
IDLE = "idle"  # the reply started, then the line marked too long before CR LF / packet end
TOO_LONG = "too long"  # max_reply_chars reached: a babbling device
#: How an attempt's reason starts where sensor characters met its command (engine, view)
CONTENTION = "invalid: bus contention"
INVALID = "invalid"  # prefix; the full reason is "invalid: <why>"


@dataclass
class Attempt:
    """One transmission of a command and what came back for it.

    ``stray_events`` are DUT characters that were already queued before this command went out
    (chatter between exchanges); they are kept apart so they are never mistaken for the reply.
    ``sequence`` and ``retry`` place the attempt in the section 7.2 scheme (sequence 0, retry 0
    is the first transmission; retry > 0 are sent without a break).
    """

    break_event: Event | None
    command_events: list[Event]
    reply_events: list[Event]
    reason: str
    end: float  # when the engine stopped listening for this attempt
    sequence: int = 0
    retry: int = 0
    stray_events: list[Event] = field(default_factory=list)
    #: a stall of the tool's own host that may have held up this attempt's read (its reply
    #: cut, its rest a late burst): set from the transcript's notes by
    #: :func:`~conformance.tool_recorder.stalled_reads.mark_reads`, None where none was noted
    stall: Stall | None = field(default=None, repr=False, compare=False)

    @property
    def ok(self) -> bool:
        return self.reason == OK

    @property
    def command_end(self) -> float | None:
        """End of the command's last stop bit: the reference of every reply/retry window."""
        return self.command_events[-1].end if self.command_events else None

    @property
    def start(self) -> float:
        if self.break_event is not None:
            return self.break_event.start
        return self.command_events[0].start if self.command_events else self.end

    @property
    def reply_text(self) -> str:
        """``decode_7e1(self.reply_events)``, decoded once per reply rather than by each
        reader (the engine's validity check, the buffer watch, every judge asking an
        exchange's ``reply_text``: some 4 decodes a reply, issue 22, matrix18). Kept with
        the list it was read from, its length and its last event: a reply only ever grows
        by appending (a golden recorder reads on into it), or is replaced whole. Only a list
        grows: any other sequence (a passive run's ``event_store.StoredEvents``, whose
        events are made at each read) is its own key, no event of it held."""
        events = self.reply_events
        made = self.__dict__.get("_text")
        if made is None or made[0] is not events or (type(events) is list and (
            made[1] != len(events) or (events and made[2] is not events[-1])
        )):  # fmt: skip
            made = (events, len(events), _last(events), decode_7e1(events))
            self.__dict__["_text"] = made
        return made[3]

    def knows_reply_text(self, text: str) -> None:
        """Keep ``text``, which its maker read as ``decode_7e1(self.reply_events)``, as
        :attr:`reply_text` (the engine's validity check decoded it already)."""
        events = self.reply_events
        self.__dict__["_text"] = (events, len(events), _last(events), text)


def _last(events: Sequence[Event]) -> Event | None:
    """The last of a reply's events, kept to tell a list grown (:attr:`Attempt.reply_text`)."""
    return events[-1] if events and type(events) is list else None


@dataclass
class Exchange:
    """A command and all its attempts (retries and repeated sequences included)."""

    command: Command | None
    text: str
    attempts: list[Attempt]
    binary: bool = False
    expect_reply: bool = True
    #: DUT characters heard after a one-shot command's reply window, by a longer listen for a
    #: sensor seen to start its replies late (:meth:`~conformance.sensor.session.
    #: SensorSession.hear_late`): its late reply, never taken for the reply
    heard_late: list[Event] = field(default_factory=list)
    #: The command sent just before this one when its last try drew no reply and the sensor
    #: had been seen to start its replies late (set by the sensor session's engine,
    #: :class:`~conformance.sensor.buffer_watch.WatchedToolRecorder`): a reply this exchange
    #: took may be that command's, late (:func:`~conformance.judges.late_before.earlier_reply`)
    late_before: Exchange | None = field(default=None, repr=False, compare=False)
    #: The command the sensor session's engine sent next, once it is: a list shared with the
    #: view's record of this stimulus, so the record judged learns of it too. A reply that
    #: command took shaped as this one's, begun soon after this one's unanswered last try,
    #: is this one's late reply (:func:`~conformance.judges.late_before.taken_next`)
    next_sent: list[Exchange] = field(default_factory=list, repr=False, compare=False)
    #: The command the sensor session's engine sent just before this one (set with
    #: ``next_sent``): a line the sensor sent over its last try, set aside as no reply, may
    #: go on into this one's window (:func:`~conformance.judges.continued_talk.continued_talk`)
    sent_before: Exchange | None = field(default=None, repr=False, compare=False)

    @property
    def last(self) -> Attempt:
        """The last attempt sent (retry timing and the line's state follow from it)."""
        return self.attempts[-1]

    @property
    def judged(self) -> Attempt:
        """The attempt the reply is judged from: the last one the DUT answered, else the
        last one sent. A retry that went unheard after an answered try says nothing about
        the reply: a sensor that needs a break before every command gave an invalid-looking
        reply, ignored the two retries without a break, and its D0 was judged as never
        answered (R-4.4-01 and four more FAILs that belong to no deviation of its).

        A D or DB command none of whose replies was accepted is judged from the reply before a
        break that held more values than the last answered one after it
        (:func:`delivered`): a new sequence of retries starts with a break (R-7.2-04), and a
        sensor whose buffer the break emptied answered it with no values although an earlier
        try delivered them; the values rules read that empty reply as five deviations of a
        sensor whose one deviation (data lost at a break, R-4.4.5-10) is its own rule's
        business, which reads the D commands again (fault combinations of 2026-12-05). So is
        one whose accepted retry holds no values after a try that held some (:func:`emptied`)."""
        for attempt in reversed(self.attempts):
            if attempt.reply_events:
                break
        else:
            return self.attempts[-1]
        if attempt is self.attempts[0] or not _is_data(self.command):
            return attempt
        # asked by every judge of the exchange, and each choice decodes every try: made once
        # per attempts list and length (attempts are only ever added, each whole)
        attempts, made = self.attempts, self.__dict__.get("_judged")
        if made is None or made[0] is not attempts or made[1] != len(attempts):
            pick = emptied if attempt.ok else delivered
            made = (attempts, len(attempts), pick(attempts, attempt, binary=self.binary))
            self.__dict__["_judged"] = made
        return made[2]

    @property
    def reply_events(self) -> list[Event]:
        return self.judged.reply_events

    @property
    def stall(self) -> Stall | None:
        """The host stall that may have held up the read of the reply judged (:attr:`judged`):
        what it shows may be the host's doing, not the DUT's (truth27)."""
        return self.judged.stall

    @property
    def reply_text(self) -> str:
        """The judged attempt's reply as 7-bit text, CR LF included (parity stripped)."""
        return self.judged.reply_text

    @property
    def reply_bytes(self) -> bytes:
        """The judged attempt's reply as raw 8N1 bytes (HB packets)."""
        return decode_8n1(self.reply_events)

    @property
    def answered(self) -> bool:
        """The DUT sent something for some attempt (valid or not): ``bool(self.reply_events)``
        read off the attempts, since :attr:`judged` is an answered attempt whenever one is
        (asked ~6,000 times a fault-matrix row, each a walk through ``judged``; issue 22)."""
        attempts = self.attempts
        if not attempts:
            return bool(self.reply_events)  # (raises as judged does)
        for attempt in attempts:  # noqa: SIM110 (a plain loop: any() over a generator costs more)
            if attempt.reply_events:
                return True
        return False

    @property
    def maybe_collided(self) -> bool:
        """The judged attempt met sensor characters that started before its command ended
        (the engine's and the view's "bus contention"): the sensor may not have heard the
        command whole. On a link whose stamps are uncertain by milliseconds, a stray
        character just before the transmission is one (over RFC 2217, fault
        stray-after-line-end: a break at 0.14..1.18 ms before the '#' ended, 9 of 267)."""
        return self.judged.reason.startswith(CONTENTION)

    @property
    def ok(self) -> bool:
        """A reply was accepted as valid (it is then the last attempt)."""
        return self.last.ok

    @property
    def start(self) -> float:
        return self.attempts[0].start

    @property
    def end(self) -> float:
        return self.last.end


def _is_data(command: Command | None) -> bool:
    return command is not None and command.kind in _DATA_KINDS


def delivered(attempts: list[Attempt], last: Attempt, *, binary: bool = False) -> Attempt:
    """Among ``attempts`` of one D or DB (``binary``) command, none accepted, with ``last``
    the last one answered: the attempt whose reply the values are read from. That is
    ``last`` unless an attempt answered before a break that came before ``last`` (an earlier
    sequence of retries, R-7.2-04) held more values (salvaged: a stray or missing CRC cut
    off; a DB packet's: those its size and type make, as the collection counts them); of
    those holding the most, the later. The data a sensor delivered stay its data until the next
    measurement, across breaks and repeated ``aDn!`` (R-4.4.5-10): fewer values to the
    retries after a break are that rule's deviation (buffer-cleared-by-break, and
    buffer-cleared-after-read, whose plain retries already found the buffer empty), which
    its own cases judge by reading the D commands again. Only retries with no break between
    them are read as they came (the last answered), as before."""
    end = next(i for i, a in enumerate(attempts) if a is last)
    broken = max((i for i in range(1, end + 1) if attempts[i].break_event), default=0)
    best, most = _fullest(attempts[:broken], binary)
    return best if best is not None and most > _values_held(last, binary) else last


def emptied(attempts: list[Attempt], accepted: Attempt, *, binary: bool = False) -> Attempt:
    """Among ``attempts`` of one D or DB command, ``accepted`` the valid reply that ended
    them: the attempt whose reply the values are read from. That is ``accepted`` unless it
    holds no values and an earlier try held some (of those holding the most, the later): a
    sensor whose buffer the read emptied (buffer-cleared-after-read) answered a retry, that
    an invalid first reply (a value without its sign) drew, with no values; reading that
    empty reply FAILed R-4.4.8-03/-04 for R-4.4.5-10's deviation and left the first reply's
    values unjudged (R-4.4.8-02 PASSed). Only an empty accepted reply is set aside: noise
    cannot empty a reply, but it can make a garbled one look like more values than a valid
    retry holds, which is then read as before."""
    if _values_held(accepted, binary):
        return accepted
    end = next(i for i, a in enumerate(attempts) if a is accepted)
    best, _ = _fullest(attempts[:end], binary)
    return best if best is not None else accepted


def _fullest(attempts: list[Attempt], binary: bool) -> tuple[Attempt | None, int]:
    """Of ``attempts``, the later of those whose replies hold the most values, and how many
    (None, 0: none holds any): where :func:`delivered` and :func:`emptied` read values from
    an earlier try."""
    best, most = None, 0
    for attempt in attempts:
        held = _values_held(attempt, binary) if attempt.reply_events else 0
        if held and held >= most:
            best, most = attempt, held
    return best, most


def _values_held(attempt: Attempt, binary: bool) -> int:
    """How many values an attempt's reply reads as (as salvaged: address, CR LF, any CRC's
    characters cut off; a packet's as its size and type give them)."""
    if binary:
        return packet_value_count(decode_8n1(attempt.reply_events))
    text = data_values_text(attempt.reply_text, False)
    return len(split_values(salvaged_values_text(text)))


@dataclass
class Measurement:
    """A measurement command, the wait for its data, and the data collection.

    ``reply_end`` is the end of the LF stop bit of the ``atttn``-type reply: ttt counts from
    there (R-4.4.5-04). ``waited_events`` holds every DUT character that arrived between that
    reply and the first D command: the service request, or evidence of chatter.
    """

    command: Command
    start: Exchange
    ttt: int | None = None
    count: int | None = None
    reply_end: float | None = None
    waited_events: list[Event] = field(default_factory=list)
    service_request_end: float | None = None
    data: list[Exchange] = field(default_factory=list)
    values: list[str] = field(default_factory=list)
    packets: list[bytes] = field(default_factory=list)
    binary_value_count: int = 0
    aborted_by: str | None = None
    #: a stall of the tool's own host that may have cut, misdated or hidden the service
    #: request of the wait (:func:`~conformance.tool_recorder.stalled_reads.wait_stall`)
    wait_stall: Stall | None = field(default=None, repr=False, compare=False)

    @property
    def binary(self) -> bool:
        return self.command.kind is _HIGH_VOLUME_BINARY

    @property
    def value_count(self) -> int:
        """Values collected so far (ASCII values, or values inside the binary packets)."""
        return self.binary_value_count if self.binary else len(self.values)

    @property
    def complete(self) -> bool:
        """All announced values were collected."""
        return self.count is not None and self.value_count >= self.count
