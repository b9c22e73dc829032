"""What the tool recorder hands back: plain records of what it sent and what came back.

The engine never judges. It keeps every attempt (break, command characters, reply characters,
and why the attempt ended) so that judges can decide timing, format and retry questions from
the records alone, and so that a misbehaving sensor leaves evidence instead of an exception.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..protocol.commands import Command, Kind
from ..transcript import Event, decode_7e1, decode_8n1

# Reasons an attempt ended. "invalid: <why>" carries the engine's own (loose) reason.
OK = "ok"
NO_REPLY = "no reply"
IDLE = "idle"  # the reply started, then the line marked too long before CR LF / packet end
TOO_LONG = "too long"  # max_reply_chars reached: a babbling device
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


@dataclass
class Exchange:
    """A command and all its attempts (retries and repeated sequences included)."""

    command: Command | None
    text: str
    attempts: list[Attempt]
    binary: bool = False
    expect_reply: bool = True

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
        answered (R-4.4-01 and four more FAILs that belong to no deviation of its)."""
        for attempt in reversed(self.attempts):
            if attempt.reply_events:
                return attempt
        return self.attempts[-1]

    @property
    def reply_events(self) -> list[Event]:
        return self.judged.reply_events

    @property
    def reply_text(self) -> str:
        """The judged attempt's reply as 7-bit text, CR LF included (parity stripped)."""
        return decode_7e1(self.reply_events)

    @property
    def reply_bytes(self) -> bytes:
        """The last attempt's reply as raw 8N1 bytes (HB packets)."""
        return decode_8n1(self.reply_events)

    @property
    def answered(self) -> bool:
        """The DUT sent something for some attempt (valid or not)."""
        return bool(self.reply_events)

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

    @property
    def binary(self) -> bool:
        return self.command.kind is Kind.HIGH_VOLUME_BINARY

    @property
    def value_count(self) -> int:
        """Values collected so far (ASCII values, or values inside the binary packets)."""
        return self.binary_value_count if self.binary else len(self.values)

    @property
    def complete(self) -> bool:
        """All announced values were collected."""
        return self.count is not None and self.value_count >= self.count
