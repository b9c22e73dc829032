"""Where a reply ends: CR LF, a binary packet's size field, or a multi-line text's ETX.

Reading a reply is "receive until the reply is complete, the line goes quiet, or the DUT has
sent too much". What "complete" and "quiet" mean depends on the reply's framing, kept here so
the engine's read loop stays one loop for all three kinds.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

from ..links.base import LineEnd, Link, StopCondition
from ..protocol.binary import packet_length
from ..protocol.framing import CR, ETX, LF, is_text
from ..protocol.timing import MULTILINE_GAP_MAX, TOLERANCE
from ..transcript import Event, EventKind
from .validity import ends_line


@dataclass(frozen=True)
class Framing:
    """How to frame one reply.

    ``binary``: an 8N1 packet framed by its size field (R-5.2-02, R-5.2-08).
    ``multiline``: an ``a<STX>`` reply may run over several lines until ETX; after a line's
    CR LF the next line may take up to 150 ms to start (R-4.4.13.1-03/04, decision A10).
    """

    idle: float  # marking after a character that ends an unfinished reply
    max_chars: int
    binary: bool = False
    multiline: bool = False
    max_text_chars: int = 0
    line_wait: float = MULTILINE_GAP_MAX + TOLERANCE  # for the next line of multi-line text

    def is_text(self, chars: list[Event]) -> bool:
        """A multi-line text reply: STX right after the address."""
        return self.multiline and is_text([e.char7 for e in chars[:2]])

    def limit(self, chars: list[Event]) -> int:
        return max(self.max_chars, self.max_text_chars) if self.is_text(chars) else self.max_chars

    def finished(self, chars: list[Event]) -> bool:
        if self.binary:
            length = packet_length(_head(chars))
            return length is not None and len(chars) >= length
        if self.is_text(chars):
            return chars[-1].char7 == ETX
        return ends_line(chars)

    def at_line_end(self, chars: list[Event]) -> bool:
        """Between lines of a multi-line text: the next line has 150 ms to start."""
        return self.is_text(chars) and ends_line(chars)

    def window(self, chars: list[Event]) -> float:
        """How long the line may mark after the last character before the read stops."""
        return self.line_wait if self.at_line_end(chars) else self.idle

    def stop(self, chars: list[Event]) -> bool:
        """Where one receive call returns so the loop can pick the next window. Asked after
        every character received; a one-line 7E1 reply (most of them) needs only its length
        and its last two characters, which is what the other three rules come to there."""
        if not (self.binary or self.multiline):
            return len(chars) >= self.max_chars or ends_line(chars)
        return len(chars) >= self.limit(chars) or self.finished(chars) or self.at_line_end(chars)

    def stop_after(self, have: list[Event], more: list[Event]) -> bool:
        """:meth:`stop` of ``have + more`` (``more`` not empty), without making that list for
        a one-line 7E1 reply: asked after every character, the copy made reading a reply
        quadratic in its length."""
        if self.binary or self.multiline:
            return self.stop(have + more)
        if len(have) + len(more) >= self.max_chars:
            return True
        before = more[-2] if len(more) > 1 else have[-1] if have else None
        # ends_line of the two, spelt out: asked per character
        return before is not None and before.wire & 0x7F == CR and more[-1].wire & 0x7F == LF

    def stop_for(self, have: list[Event]) -> StopCondition:
        """:meth:`stop_after` of ``have`` as a read's stop condition: a one-line 7E1 reply's
        as a :class:`~conformance.links.base.LineEnd` (the same rule, which a sim link checks
        inline), any other's as the call."""
        if self.binary or self.multiline:
            return partial(self.stop_after, have)
        return LineEnd(have, self.max_chars)

    def deadline(self, first: Event) -> float:
        """Hard bound for a DUT that trickles characters just inside each window."""
        per_char = first.duration + max(self.idle, self.line_wait if self.multiline else 0.0)
        return first.start + max(self.max_chars, self.max_text_chars) * per_char


def read_rest(link: Link, framing: Framing, chars: list[Event], deadline: float) -> list[Event]:
    """``chars`` (a reply begun) read on through ``link`` until the reply is complete, at its
    limit, or no character starts within the framing's window after the last one (or before
    ``deadline``, its hard bound): the engine's read loop, one for all three framings, and
    the one a reply mended after a delivery stall reads on with (:mod:`.cut_read`). Each
    read ends a window after the last character so far: the link's own idle rule only
    starts once that read has received something."""
    while not (framing.finished(chars) or len(chars) >= framing.limit(chars)):
        more = link.receive(
            min(deadline, chars[-1].end + framing.window(chars)),
            until=framing.stop_for(chars),
            idle=framing.idle,
        )
        if not more:
            break
        chars = chars + more
    return chars


def _head(chars: list[Event]) -> bytes:
    """The first three bytes of ``decode_8n1(chars)``: all a packet's size field needs, asked
    after every byte of a packet that may run to a thousand (decoding it whole each time made
    reading one quadratic)."""
    head = bytearray()
    for e in chars:
        if e.kind is EventKind.CHAR:
            head.append(e.wire)
            if len(head) == 3:
                break
    return bytes(head)
