"""A reply that may be the command before's, late: which command a reply answers.

A sensor whose every reply starts 80 ms after its command and that is deaf until then (an
Arduino Due sensor's ``delay(80)``, fault replies-after-retry) answers a command the tool
gave up on after its window while the tool sends the next one, which it never hears: that
reply lands in the next command's window and reads as its answer. Beside wrong-crc, 0D0!'s
retry went unanswered, its reply came 80 ms later, 8.33 ms after 0MC1!, and R-4.4.5-01 FAILed
"0MC1!: reply '0+22.15+1013.2+45.7DOm' does not have the form atttn" (truth15). The engine
links such an exchange to the unanswered one before it (``Exchange.late_before``, only from
a sensor seen to start its replies late); :func:`earlier_reply` says whether the reply taken
may be that one's. The words decide where they can: a reply shaped as this command's and not
as the earlier one's is this command's; otherwise it may be (or, shaped as the earlier one's
only, is) the earlier's, and a rule on this command's reply is undecided, never a FAIL on
another command's words.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ..protocol.timing import NO_BREAK_WINDOW, RESPONSE_START_MAX, RESPONSE_START_MIN, TOLERANCE
from ..tool_recorder.records import Attempt, Exchange
from ..tool_recorder.validity import fits_shape
from ..transcript import DUT, TOOL, Event, decode_7e1, escape
from ..view.sides import expected_reply_address
from .continued_talk import continued_talk

#: how near a DUT character's start must lie to a tool character's end to have waited for it
HELD_SLACK = 1e-6


def earlier_reply(ex: Exchange) -> str:
    """'' unless the reply ``ex`` took may be ``ex.late_before``'s, late: it began after that
    command's last try, within the 87 ms ``LateStartWatch`` believes a late start, naming
    no address of ``ex``'s alone, and its words do not make it ``ex``'s alone. Then
    the wording a finding gives: ``'<reply>' to 0MC1! may be 0D0!'s late reply (80.00 ms
    after it)``.

    The 87 ms count from when the reply was due (:func:`_due`: a start ``ex``'s own command
    held back), widened by the stamps' uncertainty (none on a link in virtual time): behind
    ``--echo --jitter 2`` (±1.96 ms) 0D0!'s late reply, held by 0C! on the line, began 96 ms
    after 0D0!'s last try, 0.00 ms after 0C! ended, and R-4.4.7-01 FAILed "0C!: reply
    '0+1+0+12.6' does not have the form atttnn" (truth28)."""
    before = ex.late_before
    if before is None or not ex.answered or before.last.command_end is None:
        return ""
    reply = ex.reply_events
    slack = 2 * max(reply[0].uncertainty, before.last.command_events[-1].uncertainty)
    lag = reply[0].start - before.last.command_end
    if not late_start_after(reply[0].start, ex.judged.command_events, before.last, slack):
        return ""
    # a reply naming this command's address and not the earlier one's is this one's; one
    # naming neither is no evidence either way (wrong-reply-address: D replies from '1')
    named = chr(reply[0].char7)
    address, own_address = expected_reply_address(before.text), expected_reply_address(ex.text)
    if address is not None and named != address and named == own_address:
        return ""
    text = ex.reply_text
    own = ex.command is not None and fits_shape(ex.command, text)
    theirs = before.command is not None and fits_shape(before.command, text)
    if own and not theirs:
        return ""
    how = "is" if theirs and not own else "may be"
    return (
        f"'{escape(text)}' to {escape(ex.text)} {how} {escape(before.text)}'s late reply "
        f"({lag * 1e3:.2f} ms after it)"
    )


def late_start_after(start: float, held: Sequence[Event], try_: Attempt, slack: float) -> bool:
    """Whether a DUT reply begun at ``start`` can be a late start after the try ``try_``:
    after its command, within the 87 ms ``LateStartWatch`` believes a late start, counted
    from when the reply was due (:func:`_due`: a start the tool's ``held`` characters pushed
    back), widened by ``slack`` (the stamps' uncertainty)."""
    end = try_.command_end
    if end is None or start <= end:
        return False
    return _due(start, held, HELD_SLACK + slack) - end <= NO_BREAK_WINDOW + slack


def late_reply(ex: Exchange) -> str:
    """What the DUT sent after the tool had stopped listening for a try of ``ex`` and before
    its next try ('' if nothing): a late reply, R-7.0-10's deviation, not silence. A Pico
    firmware reads its RTD for 30 ms before it answers ``aM1!``; its '00001' came 32 ms after
    each try, and "no reply although silence does not comply" was false (docs/kit.md,
    fifteenth round). For a one-shot command, what a longer listen heard after its window
    (``heard_late``, truth12). Or what the command sent next took that is this one's late
    reply (:func:`taken_next`): the replies-after-retry sensor
    beside slow-wake met 0D0!'s tries only after each break's 110 ms wake-up, and its
    reply to the last came 80 ms later, in 0C1!'s window: "0C! 0D0!: no reply to 0D0!"
    FAILed R-4.4.8-01 (truth18)."""
    strays = [e for a in ex.attempts[1:] for e in a.stray_events if e.origin == DUT]
    heard = strays + [e for e in ex.heard_late if e.origin == DUT]
    return decode_7e1(heard or taken_next(ex))


def taken_next(ex: Exchange) -> list[Event]:
    """The reply the command sent next took on its first try if it is ``ex``'s, late ([]
    if not): :func:`late_among` finds it there, and it either began before the next command
    (queued) or is not shaped as the next command's (the words decide, so no late start need
    have been seen: :func:`earlier_reply` reads the same from the other side, "is 0D0!'s
    late reply")."""
    if not ex.next_sent or not ex.next_sent[0].attempts:
        return []
    after = ex.next_sent[0]
    first = after.attempts[0]
    reply = late_among(ex, (*first.stray_events, *first.reply_events), first.command_events)
    if not reply or reply[0].start < first.start:  # begun before the next command
        return reply
    own = after.command is not None and fits_shape(after.command, decode_7e1(reply))
    return [] if own else reply


def late_among(ex: Exchange, events: Iterable[Event], held: Sequence[Event] = ()) -> list[Event]:
    """``ex``'s late reply among ``events`` (what the wire carried after its last try), []
    if none: ``ex``'s last try drew no reply, the DUT's first character began within the
    87 ms ``LateStartWatch`` believes a late start after it, names the address ``ex``'s
    would, and the DUT's characters are shaped as ``ex``'s reply. A start the tool's own
    character pushed back (``held``: the command then on the line; the sim's one wire sends
    a sensor character due meanwhile at its end) counts from when it was due: beside
    slow-wake, 0C9!'s 0D0! reply, due 80 ms after the last try, began 88.33 ms after it, at
    the end of 0IMC_001!'s seventh character, and "no reply to 0D0!" FAILed R-4.4.8-01
    (truth20)."""
    end = ex.last.command_end if ex.attempts else None
    if end is None or ex.last.reply_events or ex.command is None:
        return []
    reply = sorted((e for e in events if e.origin == DUT), key=lambda e: e.start)
    if not reply or not 0 < _due(reply[0].start, held) - end <= NO_BREAK_WINDOW:
        return []
    address = expected_reply_address(ex.text)
    if address is not None and chr(reply[0].char7) != address:
        return []
    return reply if fits_shape(ex.command, decode_7e1(reply)) else []


def _due(start: float, held: Sequence[Event], slack: float = HELD_SLACK) -> float:
    """When a DUT character that began at ``start`` was due: the start of the tool character
    that held the line until then (one ending there, within ``slack``), else ``start``."""
    for e in held:
        if e.origin == TOOL and e.start < start and abs(e.end - start) < slack:
            return e.start
    return start


def late_shown(ex: Exchange) -> str:
    """``0M1! -> late '00001<CR><LF>'``: the command and the first line of its late reply."""
    text = late_reply(ex)
    return f"{escape(ex.text)} -> late '{escape(text[: text.find(chr(10)) + 1] or text)}'"


def late_answer(ex: Exchange) -> str:
    """``answered only after the reply window: 0M1! -> late '00001<CR><LF>'`` for an
    ``ex`` unanswered in its windows whose reply came after them (:func:`late_reply`), ''
    otherwise: the one wording of the rules that leave such a reply to R-7.0-10."""
    if ex.answered or not late_reply(ex):
        return ""
    return f"answered only after the reply window: {late_shown(ex)}"


def heard_late(ex: Exchange) -> bool:
    """Whether a one-shot ``ex`` unanswered in its window drew a reply the longer listen for
    a sensor seen late heard (``ex.heard_late``): an answer all the same, to a command that
    was sent once with nothing after it. standby-ignored + replies-after-retry answered
    R-7.0-15's a! 101.90 ms after a reply, 80 ms late, and the rule PASSed "stayed silent"
    (truth12). Not where it names another address (:func:`late_elsewhere`): that is no
    answer to ``ex``."""
    heard = any(e.origin == DUT for e in ex.heard_late)
    return not ex.answered and heard and not late_elsewhere(ex)


def late_elsewhere(ex: Exchange) -> str:
    """What a one-shot ``ex``'s longer listen heard ('' if nothing) when it names another
    address than ``ex``'s reply would: the sensor's late reply to a command before it, begun
    over ``ex``, which it may not have heard; neither an answer to ``ex`` nor silence
    (replies-after-retry + answers-foreign-address: 'z<CR><LF>' to zI!, heard after 0!,
    FAILed R-7.0-14; only that rule checked the address, truth15 made it the one rule of
    every reader of ``heard_late``)."""
    if ex.answered:
        return ""
    heard = [e for e in ex.heard_late if e.origin == DUT]
    address = expected_reply_address(ex.text)
    if not heard or address is None or heard[0].char7 == ord(address[0]):
        return ""
    return decode_7e1(heard)


def answered_late(ex: Exchange) -> str:
    """How ``ex``'s reply came late ('' if it did not): unanswered in its windows with its
    reply after them (:func:`late_answer`), or answered with what may be the command
    before's late reply (:func:`earlier_reply`) or the next line of a talk set aside before
    it (:func:`~.continued_talk.continued_talk`). The one test of the rules that leave a late
    reply to R-7.0-10 (late_only, late_among, undecided_if_late, the D replies)."""
    if not ex.answered:
        return late_answer(ex)
    return earlier_reply(ex) or continued_talk(ex)


def service_request_too_soon(ex: Exchange) -> str:
    """'' unless the reply ``ex`` took is a bare ``a<CR><LF>`` (a service request's words)
    begun sooner after the command than R-7.0-09 lets any answer begin: a sensor that sends
    a service request on its own (after ttt = 000, say) puts it on the line whenever it is
    ready, and one due while the tool's command was still on the line comes right after
    it. Read as the command's reply, an empty aD0! after values were announced FAILed
    R-4.4.8-03/-04 ("0 values were returned for 2 announced") while the real D0 reply, with
    its values, came 8 ms later (service-request-after-ttt-zero + inter-char-gap). Whether
    it answers the command is unread. Else the wording a finding gives."""
    lead = _bare_request_lead(ex)
    if lead is None or lead >= RESPONSE_START_MIN:
        return ""
    return (
        f"'{escape(ex.reply_text)}' to {escape(ex.text)} began {lead * 1e3:.2f} ms after it, "
        "too soon to answer it, and has a service request's words"
    )


def service_request_too_late(ex: Exchange) -> str:
    """'' unless the reply ``ex`` took is a bare ``a<CR><LF>`` begun after R-7.0-10's window
    (15.40 ms), in the longer listen of a patient recorder: a reply that late may as well be
    a service request the sensor sent on its own. replies-after-retry beside
    service-request-after-ttt-zero: 0M1!'s '00002' met the retry, the request after it came
    29.33 ms after the 0D0! that followed, and R-4.4.8-04 FAILed "D0 returned no values
    although 2 were announced" while D0's values came 80 ms after it (truth19). Else the
    wording a finding gives."""
    lead = _bare_request_lead(ex)
    if lead is None or lead <= RESPONSE_START_MAX + TOLERANCE:
        return ""
    return (
        f"'{escape(ex.reply_text)}' to {escape(ex.text)} began {lead * 1e3:.2f} ms after it, "
        "past the window a reply begins in, and has a service request's words"
    )


def _bare_request_lead(ex: Exchange) -> float | None:
    """How long after its command the reply ``ex`` took began, where that reply is a bare
    ``a<CR><LF>`` (a service request's words); None otherwise."""
    if not ex.answered or not ex.attempts or ex.last.command_end is None:
        return None
    text = ex.reply_text
    if len(text) != 3 or not text.endswith("\r\n"):
        return None
    return ex.reply_events[0].start - ex.last.command_end
