"""Who sent what, when the recording does not say: direction inferred from the protocol.

A capture of the single SDI-12 wire has every character but not its sender (origin
:data:`~.segments.BUS`). The protocol says a lot: only the recorder sends a break, and the
characters right after one are its command; a command ends in ``!`` and no sensor may talk
before it does; the reply starts with the addressed sensor's address 7.93-15.4 ms after the
command; a service request ``a<CR><LF>`` comes after an ``atttn`` announcement; a sensor's line
ends in CR LF. Each run of characters is read against these cues, and each gets a
:class:`Direction` saying which cue it rests on. Where no cue settles it the direction stays
unknown (``side`` None) or, where one reading is likely but not certain, ``sure`` is False and
``how`` says what is doubtful (two talkers, an address mismatch, a line answering no
command): never a silent guess.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

from ..protocol.binary import packet_length
from ..protocol.commands import ADDRESS_CHARS, Kind, command_or_none
from ..protocol.framing import STX
from ..protocol.responses import parse_measurement_reply_for, split_line
from ..protocol.timing import (
    MARKING_AFTER_BREAK,
    MULTILINE_GAP_MAX,
    NO_BREAK_WINDOW,
    RESPONSE_START_MAX,
    RESPONSE_START_MIN,
    TOLERANCE,
)
from ..transcript import Event, EventKind, decode_7e1, decode_8n1, escape
from .sides import RECORDER, SENSOR, expected_reply_address

#: How long past an announced ttt a service request is still read as one (a late one is a
#: finding on the sensor, not a reason to doubt who sent it).
SERVICE_REQUEST_GRACE = 1.0


@dataclass(frozen=True)
class Direction:
    """Which side sent an event, and the protocol cue that says so."""

    side: str | None  # RECORDER, SENSOR, or None: unknown
    how: str
    sure: bool = True


@dataclass
class _State:
    """What the reading so far implies about the next run."""

    after_break: bool = False
    #: the break just sent came while the sensor's line was still coming (its last
    #: character ended less than a character before the break began, the line unfinished)
    broke_into_line: bool = False
    last_side: str | None = None
    last_end: float = float("-inf")
    last_uncertainty: float = 0.0  # of the stamp at last_end
    command: str = ""  # the recorder's current transmission so far
    command_end: float = float("-inf")
    awaiting_reply: bool = False  # a command ended in '!' and nothing answered yet
    reply: list[Event] = field(default_factory=list)  # the sensor's current message
    reply_to: str = ""  # the command it answers ("" for unsolicited lines)
    announced: dict[str, float] = field(default_factory=dict)  # address -> data ready at


def _runs(chars: list[Event]) -> list[list[Event]]:
    """Bursts of one talker: a new run after a ``!`` or an LF (where the other side may take
    over), after a pause in which a turnaround is possible (7.93 ms), or where a character
    overlaps the one before (two talkers). Shorter pauses keep one talker's run whole, so a
    gappy command or reply is still read as one. A pause is "possible turnaround" only when
    it surely is: where the stamps may be off (a host that got bytes in a batch and stamped
    them back to back, so one stamp sits late and the gap before it looks long), a pause that
    may have been shorter than 7.93 ms keeps the run whole; the monitor cut the recorder's
    ``0R0!`` into an unknown ``0`` and a command ``R0!`` at such a gap of its own making."""
    out: list[list[Event]] = []
    for e in chars:
        if out:
            prev = out[-1][-1]
            gap = e.start - prev.end
            slack = _slack(prev, e)
            if -slack < gap < RESPONSE_START_MIN + slack and prev.char7 not in (0x21, 0x0A):
                out[-1].append(e)
                continue
        out.append([e])
    return out


def _slack(a: Event, b: Event) -> float:
    """How far two stamps may seem to overlap without two talkers: a capture stamps a
    character's end from its start, so back-to-back characters may overlap by a sample."""
    return a.uncertainty + b.uncertainty + 1e-9


def infer_directions(events: Iterable[Event]) -> list[tuple[Event, Direction]]:
    """A :class:`Direction` for every break and character of ``events`` (notes are left out);
    the events' own origins are not looked at."""
    return list(iter_directions(events))


def iter_directions(events: Iterable[Event]) -> Iterator[tuple[Event, Direction]]:
    """:func:`infer_directions` one pair at a time, as each run is read: a caller that
    keeps less than every pair (``view.segments.read_view`` keeps a byte an event) never
    holds the list (an hour's capture: 340,000 pairs, 25 MB at the peak of its judging)."""
    ordered = by_start_and_end(events)
    state = _State()
    pending: list[Event] = []

    def flush() -> Iterator[tuple[Event, Direction]]:
        for run in _runs(pending):
            direction = _classify(run, state)
            yield from ((e, direction) for e in run)
            _advance(state, run, direction)
        pending.clear()

    for e in ordered:
        if e.kind is EventKind.BREAK:
            yield from flush()
            yield e, Direction(RECORDER, "a break: only the recorder sends one")
            state.broke_into_line = _line_coming(state, e)
            state.after_break, state.awaiting_reply = True, False
            state.command, state.reply = "", []
            state.last_side, state.last_end = RECORDER, e.end
            state.last_uncertainty = e.uncertainty
        elif e.kind is EventKind.CHAR:
            if pending and e.start < pending[-1].end - _slack(pending[-1], e):
                yield from flush()  # an overlap: the runs on either side are read one by one
            pending.append(e)
    yield from flush()


def by_start_and_end(events: Iterable[Event]) -> list[Event]:
    """``events`` but notes sorted stably by ``(start, end)``: the list itself where it is
    one so already (a capture's, a view's: one pass, no copy), else a sorted copy. Sorting
    made a key tuple an event (an hour's capture: 357,000 of them, ~25 MB at the peak of
    its loading); a pair is taken as in order exactly when the sort would leave it so (its
    keys compared as the sort compares them), so the list is the one the sort gives."""
    note = EventKind.NOTE
    if isinstance(events, list):
        before = None
        for e in events:
            if e.kind is note:
                break
            if before is not None and (e.start, e.end) < (before.start, before.end):
                break
            before = e
        else:
            return events
    return sorted((e for e in events if e.kind is not note), key=lambda e: (e.start, e.end))


def _classify(run: list[Event], s: _State) -> Direction:
    text = decode_7e1(run)
    start = run[0].start
    gap = start - s.last_end
    slack = run[0].uncertainty + s.last_uncertainty  # how far the stamps may misplace gap
    overlap = gap < -(2 * run[0].uncertainty + 1e-9)
    shown = escape(text[:12]) + ("..." if len(text) > 12 else "")
    if overlap:
        other = SENSOR if s.last_side == RECORDER else RECORDER
        return Direction(
            other if s.last_side else None,
            f"'{shown}' overlaps the {s.last_side or 'line'}'s characters: two talkers",
            sure=False,
        )
    if s.after_break:
        if s.broke_into_line and "!" not in text and gap < MARKING_AFTER_BREAK - TOLERANCE:
            # the sensor cannot hear a break while it sends: the rest of its character
            # under the break ends after it, and a UART reads that tail as a character
            # (breaks-over-long-reply: '~' 1.1 ms after the break, then '0D0!' 23 ms after)
            return Direction(
                SENSOR,
                f"'{shown}' {_ms(gap)} after a break over the sensor's line still coming: "
                "that line's rest, or the recorder's command too soon after the break",
                sure=False,
            )
        if text.endswith("!") or "!" not in text:
            return Direction(RECORDER, f"'{shown}' right after a break: the recorder's")
        return Direction(RECORDER, f"'{shown}' right after a break", sure=False)
    if s.last_side == RECORDER and s.command and not s.command.endswith("!"):
        return Direction(
            RECORDER, f"'{shown}' continues the recorder's '{escape(s.command)}' (no '!' yet)"
        )
    if s.last_side == SENSOR and s.reply and not _message_done(s):
        if gap < RESPONSE_START_MIN + slack:
            return Direction(SENSOR, f"'{shown}' continues the sensor's line after {_ms(gap)}")
        if _is_text(s.reply) and gap <= MULTILINE_GAP_MAX + TOLERANCE + slack:
            return Direction(SENSOR, f"'{shown}': the next line of multi-line text")
    if s.awaiting_reply and gap <= NO_BREAK_WINDOW + slack:
        found = _as_reply(text, shown, gap, slack, s)
        if found is not None:
            return found
    if _looks_like_command(text):
        if s.last_side == SENSOR and s.reply and not _message_done(s):
            return Direction(
                RECORDER,
                f"'{shown}' has a command's shape, but the sensor's line before it never "
                "ended: two talkers, or a line that contains a command",
                sure=False,
            )
        return Direction(RECORDER, f"'{shown}' has a command's shape (address ... '!')")
    sr = _as_service_request(text, start, s)
    if sr is not None:
        return sr
    if text.endswith("\r\n") or text.endswith("\x03"):
        return Direction(
            SENSOR, f"'{shown}' ends like a sensor's line but answers no command", sure=False
        )
    return Direction(None, f"'{shown}': no protocol cue (not after a break, no '!', no CR LF)")


def _line_coming(s: _State, brk: Event) -> bool:
    """Whether the sensor's line was still coming when ``brk`` began: its message so far
    unfinished, its last character read ending less than two character times before the
    break (the character the break began over reads as part of the break where its spacing
    bits run into it: 9.0 ms between the last one read and the break in aHA!'s D0); or,
    a command awaiting its reply, the reply may have begun under the break (a sensor cannot
    hear a break while it sends: pause-once's aD0! answered 9 ms into the break)."""
    if s.awaiting_reply:
        return brk.end - s.command_end > RESPONSE_START_MIN
    return (
        s.last_side == SENSOR
        and bool(s.reply)
        and not _message_done(s)
        and brk.start - s.last_end < 2 * MARKING_AFTER_BREAK
    )


def _as_reply(text: str, shown: str, gap: float, slack: float, s: _State) -> Direction | None:
    """The first run after a command ending in '!' within 87 ms: the reply, or a retry.
    ``slack``: how far the stamps may misplace ``gap`` (a start they cannot place outside
    the window is not a reason to doubt who sent it; the timing judges weigh it)."""
    window = RESPONSE_START_MIN - slack <= gap <= RESPONSE_START_MAX + TOLERANCE + slack
    when = f"{_ms(gap)} after '{escape(s.command)}'" + ("" if window else " (outside 7.93-15.4 ms)")
    if _binary_command(s.command):
        return Direction(SENSOR, f"a packet answering '{escape(s.command)}', {when}", window)
    if _looks_like_command(text):
        return None  # the recorder again: a retry or its next command
    expected = expected_reply_address(s.command)
    first = text[:1]
    if expected is None or first == expected:
        return Direction(SENSOR, f"reply: '{shown}' starts with the address {when}", window)
    if text.endswith("\r\n"):
        return Direction(
            SENSOR,
            f"reply? '{shown}' ends in CR LF {when} but starts with '{escape(first)}', "
            f"not '{expected}': address mismatch",
            sure=False,
        )
    return None


def _as_service_request(text: str, start: float, s: _State) -> Direction | None:
    if len(text) != 3 or text[1:] != "\r\n" or text[0] not in ADDRESS_CHARS:
        return None
    ready = s.announced.get(text[0])
    if ready is None:
        return Direction(
            SENSOR, f"'{escape(text)}': a service request's shape, no announcement", sure=False
        )
    if start <= ready + SERVICE_REQUEST_GRACE:
        return Direction(SENSOR, f"service request '{escape(text)}' after the announced ttt")
    return Direction(SENSOR, f"'{escape(text)}' long after the announced ttt", sure=False)


def _advance(s: _State, run: list[Event], d: Direction) -> None:
    text = decode_7e1(run)
    s.after_break = False
    if d.side == RECORDER:
        if s.last_side != RECORDER or s.command.endswith("!"):
            s.command = ""
        s.command += text
        s.command_end = run[-1].end
        s.awaiting_reply = s.command.endswith("!")
        s.reply, s.reply_to = [], ""
    elif d.side == SENSOR:
        if s.last_side != SENSOR or _message_done(s):
            s.reply, s.reply_to = [], s.command if s.awaiting_reply else ""
        s.reply += run
        s.awaiting_reply = False
        _note_announcement(s)
    s.last_side = d.side or s.last_side
    if run[-1].end >= s.last_end:
        s.last_end, s.last_uncertainty = run[-1].end, run[-1].uncertainty


def _note_announcement(s: _State) -> None:
    """An ``atttn``-type reply to a measurement: a service request may follow after ttt."""
    command = command_or_none(s.reply_to)
    if command is None or not command.starts_measurement or not _message_done(s):
        return
    body, _ = split_line(decode_7e1(s.reply))
    parsed = parse_measurement_reply_for(body, command)
    if parsed.ttt is not None:
        s.announced[command.address] = s.reply[-1].end + parsed.ttt


def _message_done(s: _State) -> bool:
    if _binary_command(s.reply_to):
        length = packet_length(decode_8n1(s.reply))
        return length is not None and len(s.reply) >= length
    text = decode_7e1(s.reply)
    if _is_text(s.reply):
        return text.endswith("\x03")
    return text.endswith("\n")


def _is_text(reply: list[Event]) -> bool:
    return len(reply) > 1 and reply[1].char7 == STX


def _looks_like_command(text: str) -> bool:
    return (
        text.endswith("!")
        and (text[:1] in ADDRESS_CHARS or text[:1] == "?")
        and "\r" not in text
        and "\n" not in text
    )


def _binary_command(text: str) -> bool:
    command = command_or_none(text)
    return command is not None and command.kind is Kind.BINARY_DATA


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:.2f} ms"
