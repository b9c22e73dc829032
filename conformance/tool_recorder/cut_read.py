"""A reply the engine's read cut at a delivery stall, mended from the characters that came late.

On a real link the engine's read of a reply ends when no character has *arrived* for the
framing's idle window (and the link's latency bound) after the last one. On a loaded host a
delivery can stall longer than that (truth23: behind ``emulate --echo --jitter 2`` at load ~22,
0IHB_010!'s record was read as ``'0,XB, ,sa'``, 9 of its 32 characters): the read ends, the try
is taken as cut off (IDLE) and retried, and when the rest arrives its stamps put it right behind
the ninth character, back to back as the wire carried it (a burst is laid back to back after
the previous frame, :func:`~conformance.links.stamps.chunk_frames`). The transcript then holds
the reply whole while the record judged holds the cut one: R-6.2-02 FAILed "does not end with
';'" for a sensor whose only fault was its CRC.

The rest comes in the next try's read: queued before it went out (its ``stray`` characters),
or after, stamped before its command ended (its collided characters). Those of them that the
stamps place inside the cut read's windows, one after the other, as the read itself would have
taken them, are the cut reply's: they are added to it and it is judged again, and they are
neither the next try's strays nor a collision with it. The rule is the read's own (and the
view's, which cuts a rebuilt reply where the stamps idle, :mod:`conformance.view.rebuilt_records`),
so a reply that really paused past the window stays cut, as it always was. Only links whose
deliveries can lag their stamps (not virtual-time ones) are mended. The residue stays cut as
before: a rest that arrives after the next try's reply has begun, and a stall longer than the
window and the rest together, whose burst is laid to end at its arrival and so shows a gap
past the window. Joining across such a gap where the link's uncertainty covers it was tried
(truth25, host stalls of 80-200 ms every 0.3-0.9 s) and joined the next try's reply to the
cut one ('...+16.<0x00>00+15.000...'): not done.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from ..links.base import Link
from ..transcript import Event, decode_7e1
from .records import IDLE, TOO_LONG, Attempt, Exchange
from .reply_end import Framing, read_rest

#: the NOTE a mended reply leaves where its rest begins (the count of characters added
#: follows): the report shows why characters read in a later try belong to this one
STALL_NOTE = (
    "the read of the reply before ended at a delivery stall; characters that came after it, "
    "stamped inside its windows, were added to it: "
)


@dataclass
class CutRead:
    """An attempt whose read ended IDLE on a link whose deliveries may lag (:func:`cut`).

    ``judge`` checks a finished reply, given its text (None: a binary packet), as the
    engine does: OK or ``invalid: why``."""

    attempt: Attempt
    framing: Framing
    link: Link
    judge: Callable[[list[Event], str | None], str]
    #: the exchange the attempt belongs to, once known: its cached choice of the judged
    #: attempt is dropped when the reply grows
    exchange: Exchange | None = field(default=None, repr=False)

    def continuation(self, chars: list[Event]) -> int:
        """How many of ``chars`` (in arrival order) continue the cut reply: each began
        inside the read's window after the one before (its idle, or the next line's wait in
        a multi-line text) and before the read's hard bound, and the reply was not complete
        or at its limit yet."""
        framing = self.framing
        reply = self.attempt.reply_events
        if not reply:
            return 0
        hard = framing.deadline(reply[0])
        have = list(reply)
        taken = 0
        for char in chars:
            if framing.finished(have) or len(have) >= framing.limit(have):
                break
            if char.start >= min(hard, have[-1].end + framing.window(have)):
                break
            have.append(char)
            taken += 1
        return taken

    def mend(self, chars: list[Event], *, read_on: bool = False) -> list[Event]:
        """Add the leading ``chars`` that continue the cut reply to it, judge it again, and
        return the rest (none taken: ``chars`` as they were). ``read_on``: where all of
        them were its rest and nothing was read after them (the next try drew no reply of
        its own), read on as the cut read would have, for the rest still coming."""
        taken = self.continuation(chars)
        if not taken:
            return chars
        attempt, framing = self.attempt, self.framing
        taken_before = len(attempt.reply_events)
        reply = attempt.reply_events + chars[:taken]
        if read_on and taken == len(chars):  # all of it the rest: more may be coming
            # as the cut read would have (the engine's loop)
            reply = read_rest(self.link, framing, reply, framing.deadline(reply[0]))
        attempt.reply_events = reply
        if framing.finished(reply) or framing.at_line_end(reply):
            text = None if framing.binary else decode_7e1(reply)
            attempt.reason = self.judge(reply, text)
            if text is not None:
                attempt.knows_reply_text(text)
        else:
            attempt.reason = TOO_LONG if len(reply) >= framing.limit(reply) else IDLE
        if self.exchange is not None:
            self.exchange.__dict__.pop("_judged", None)
        self.link.transcript.note(chars[0].start, f"{STALL_NOTE}{len(reply) - taken_before}")
        return chars[taken:]

    def mend_met(
        self, collided: list[Event], first: Event | None, *, read_on: bool = False
    ) -> list[Event]:
        """:meth:`mend` of the characters that met the next try's transmission (``first``:
        its break or first character): the rest of the cut reply is no collision of that
        try's when the stamps put all of it before the try began, and stays one (the
        whole list, so the try is judged as met) when it ran on into it: the DUT was still
        talking when the tool, blind to it, sent the try."""
        rest = self.mend(collided, read_on=read_on)
        taken = len(collided) - len(rest)
        if taken and first is not None and collided[taken - 1].end > first.start:
            return collided
        return rest


def cut(
    attempt: Attempt,
    framing: Framing,
    link: Link,
    *,
    judge: Callable[[list[Event], str | None], str],
) -> CutRead | None:
    """The attempt to mend from the next try's characters: one whose read ended IDLE with a
    reply begun, on a link whose deliveries may lag their stamps (None otherwise: on a
    virtual clock every character is delivered at its stamp, so the read's end is the
    line's)."""
    if link.info.virtual_time or attempt.reason != IDLE or not attempt.reply_events:
        return None
    return CutRead(attempt, framing, link, judge)
