"""``Transmission.binary`` kept per length of the characters (issue 22, matrix19), as
``text`` and ``command`` are: a stimulus's records ask it twice an attempt (the reply's
framing, whether it is complete), each a match of the stem before. Kept, it must still say
what the stem says at every length the transmission grows through (the cut appends a
command's characters one at a time; a reply framed as a packet only once ``aDBn!`` is
whole), and a reply framed by it must change with it."""

from __future__ import annotations

import pytest

from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view.segments import Transmission

CHAR = 8.33e-3


def _chars(text: str, t0: float, origin: str = TOOL) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, t0 + i * CHAR, t0 + (i + 1) * CHAR, wire=to_wire_7e1(ord(c)))
        for i, c in enumerate(text)
    ]


def _as_matched(t: Transmission) -> bool:
    """What the stem's match says (the property before it was kept)."""
    d = t.data_index
    return d is not None and d[0]


@pytest.mark.parametrize(
    "text", ["0DB1!", "0D1!", "0DB12!", "0DB!", "0M!", "0DB1!\r\n", "0DBx!", "aDB999!", "0I!"]
)
def test_binary_follows_the_characters_as_they_come(text):
    chars = _chars(text, 0.0)
    t = Transmission(None, chars[:1])
    seen = []
    for e in chars[1:]:
        seen.append((t.binary, _as_matched(t)))
        t.chars.append(e)
        seen.append((t.binary, _as_matched(t)))
    assert all(kept == matched for kept, matched in seen), (text, seen)
    assert t.binary is _as_matched(t)


def _fresh(chars: list[Event], heard: list[Event]) -> Transmission:
    t = Transmission(None, list(chars))
    t.heard.extend(heard)
    return t


def test_a_reply_is_framed_as_a_packet_once_the_command_is_whole():
    chars = _chars("0DB1!", 0.0)
    heard = _chars("0\n12", 0.1, DUT)  # 7E1 framing ends it at the LF; 8N1 does not
    t = _fresh(chars[:-1], heard)
    assert not t.binary and len(t.reply) == 2
    t.chars.append(chars[-1])  # the '!': now aDB1!, whose reply is an 8N1 packet
    assert t.binary
    assert t.reply == _fresh(chars, heard).reply and len(t.reply) != 2
