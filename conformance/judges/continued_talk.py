"""A reply that may be the next line of a talk the tool set aside: which command it answers.

A sensor that sends its replies as several lines (an ENG20009 Arduino Due sketch, outside34:
``NO DATA @n``, ``FINAL DATA @2`` and ``0``, each 100 ms after the one before, its receiver
off meanwhile) is still talking when the tool, which read the first line, sends its next
command. A line that met the tool's command is set aside as contention; the line after it,
begun in the next command's window, reads as that command's answer: '0<CR><LF>' "answered"
0R5! 27 ms after it, and R-4.4.8.1-01 PASSed on it. A line begun within the 150 ms a
multi-line text's next line may take (R-4.4.13.1-03) after a set-aside line that was no
reply to the command it met may be that talk's next line: a rule on the command's reply is
undecided (:func:`continued_talk`, read by :func:`~.late_before.answered_late`), never a
PASS or a FAIL on another command's words.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..protocol.commands import Command, command_or_none
from ..protocol.framing import LF
from ..protocol.timing import MULTILINE_GAP_MAX
from ..tool_recorder.records import Attempt, Exchange
from ..tool_recorder.validity import fits_shape
from ..transcript import DUT, Event, EventKind, decode_7e1, escape
from ..view.runs import Segment


def _sent_before(ex: Exchange) -> Exchange | None:
    """The command sent before ``ex``, where it is still held: the engine links it weakly
    (a proxy, so the chain of a run's exchanges makes no reference cycle)."""
    sent = ex.sent_before
    if sent is None:
        return None
    try:
        sent.attempts  # noqa: B018 (a dead proxy raises here)
    except ReferenceError:
        return None
    return sent


def continued_talk(ex: Exchange) -> str:
    """'' unless the reply ``ex`` took may be the next line of a talk set aside before it
    (:func:`next_line_of`): a line the sensor sent over the try before the one that drew the
    reply (of ``ex``, or the last of the command sent before, ``ex.sent_before``) or over
    that try itself. Else the wording a finding gives."""
    if not ex.answered or not ex.attempts:
        return ""
    judged = ex.judged
    reply = judged.reply_events
    if not reply:
        return ""
    index = next((i for i, a in enumerate(ex.attempts) if a is judged), 0)
    before: tuple[Attempt, Exchange] | None = None
    if index > 0:
        before = (ex.attempts[index - 1], ex)
    elif (sent := _sent_before(ex)) is not None and sent.attempts:
        before = (sent.last, sent)
    own = [e for e in judged.stray_events if e.start < reply[0].start]
    if own or before is None:
        owner, aside = ex, own
    else:
        owner, aside = before[1], list(before[0].stray_events)
    found = next_line_of(aside, owner.command, reply[0])
    if found is None:
        return ""
    line, gap = found
    return (
        f"'{escape(ex.reply_text)}' to {escape(ex.text)} may be the next line of a talk "
        f"whose line ending '{escape(line)}' the sensor sent over {escape(owner.text)}, "
        f"{gap * 1e3:.2f} ms before it began {SET_ASIDE}"
    )


#: how :func:`continued_talk`'s wording ends (a finding adds no timing rule to it)
SET_ASIDE = "(a reply to no command, set aside)"


def next_line_of(
    aside: Sequence[Event], command: Command | None, first: Event
) -> tuple[str, float] | None:
    """The last line of ``aside`` (what the sensor sent over a command, set aside as no
    reply) and the gap to ``first`` (a reply's first character), where the reply may be
    that talk's next line: ``aside`` ends with the line's LF, the line is not shaped as a
    reply to ``command`` (the one it met: a late reply to that is :mod:`.late_before`'s)
    nor a bare ``a<CR><LF>`` (a service request is a line of its own), and ``first`` began
    within the 150 ms a multi-line text's next line may take (R-4.4.13.1-03), plus the
    stamps' uncertainty, after its LF. None otherwise."""
    said = [e for e in aside if e.kind is EventKind.CHAR and e.origin == DUT]
    if not said or said[-1].char7 != LF:
        return None
    line = _last_line(said)
    text = decode_7e1(line)
    if len(text) <= 3 or (command is not None and fits_shape(command, text)):
        return None
    slack = 2 * max(first.uncertainty, line[-1].uncertainty)
    gap = first.start - line[-1].end
    return (text, gap) if 0 <= gap <= MULTILINE_GAP_MAX + slack else None


def segment_continues(before: Segment | None, seg: Segment) -> bool:
    """Whether ``seg``'s reply may be the next line of what the sensor sent over the command
    of ``before`` (the segment before it) or over ``seg``'s own, set aside as contention
    (:func:`next_line_of`): no reply to ``seg``'s command, so its start times nothing of how
    soon the sensor answers (a '0<CR><LF>' 5.00 ms after 0R4!, the third line of an aD-style
    reply the sketch began two commands before, FAILed R-7.0-09, truth37)."""
    if not seg.reply:
        return False
    own = [e for e in seg.contention if e.start < seg.reply[0].start]
    owner = seg if own or before is None else before
    aside = own or (before.contention if before is not None else [])
    if not aside:
        return False
    return next_line_of(aside, command_or_none(owner.text), seg.reply[0]) is not None


def _last_line(chars: list[Event]) -> list[Event]:
    """The characters of the last line of ``chars`` (which end with its LF)."""
    start = len(chars) - 1
    while start > 0 and chars[start - 1].char7 != LF:
        start -= 1
    return chars[start:]
