"""``Exchange.answered`` read off the attempts (issue 22, live28) is ``bool(reply_events)``,
what it was: the judged attempt is an answered one whenever one is, whatever the command
(a D or DB command's values are read from the fullest reply before a break, or an earlier
try than an empty accepted one: :func:`~conformance.tool_recorder.records.delivered`,
:func:`~conformance.tool_recorder.records.emptied`). Every exchange of up to three attempts
of each kind below, with and without a break before each, for a D, a DB and an M command."""

from __future__ import annotations

from itertools import product

import pytest

from conformance.protocol.commands import parse_command
from conformance.tool_recorder.records import OK, Attempt, Exchange
from conformance.transcript import EventKind, encode_7e1, wire_event

_BREAK = wire_event(EventKind.BREAK, "tool", 0.0, 0.013)
_CMD = [wire_event(EventKind.CHAR, "tool", 0.02, 0.028, w) for w in encode_7e1("0D0!")]


def _reply(text: str) -> list:
    return [
        wire_event(EventKind.CHAR, "sensor", 0.05 + i * 0.008, 0.058 + i * 0.008, w)
        for i, w in enumerate(encode_7e1(text))
    ]


#: (reply, reason) of one attempt: none, empty of values, values with a stray CRC, values
KINDS = (
    ("", "no reply"),
    ("0\r\n", OK),
    ("0\r\n", "invalid: no CR LF at the end"),
    ("0+1+2IOA\r\n", "invalid: unexpected CRC characters"),
    ("0+1+2\r\n", OK),
    ("\x010\x00\x04", "invalid: short packet"),
)


@pytest.mark.parametrize("code", ["0D0!", "0DB0!", "0M!"])
def test_answered_is_whether_the_judged_attempt_has_a_reply(code):
    command = parse_command(code)
    seen = 0
    for n in (1, 2, 3):
        for kinds in product(KINDS, repeat=n):
            for breaks in product((False, True), repeat=n):
                attempts = [
                    Attempt(_BREAK if brk else None, _CMD, _reply(text), reason, 1.0, retry=i)
                    for i, ((text, reason), brk) in enumerate(zip(kinds, breaks, strict=True))
                ]
                ex = Exchange(command, code, attempts, binary=code.startswith("0DB"))
                assert ex.answered is bool(ex.reply_events)
                seen += ex.answered
    assert seen > 0


def test_no_attempt_raises_as_before():
    ex = Exchange(parse_command("0D0!"), "0D0!", [])
    with pytest.raises(IndexError):
        ex.answered  # noqa: B018
