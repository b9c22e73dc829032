"""A stimulus's records frame its reply as the character-by-character loops did (issue 22,
fault-matrix round 10): a one-line reply's first LF is found in one pass over the wire bytes
(:attr:`Transmission.reply`), and a reply with no gap longer than the idle is kept whole
without a step per character (``rebuilt_records._framed``). Each is held to the plain loop,
kept here, on replies of every shape: with and without an LF, bad parity, a wire that is no
byte, multi-line text, gaps over the idle before and after an LF, a NaN stamp."""

from __future__ import annotations

import math
import random

import pytest

from conformance.protocol.framing import ETX, LF, STX
from conformance.protocol.timing import MULTILINE_GAP_MAX, TOLERANCE
from conformance.tool_recorder.policy import Policy
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view import rebuilt_records
from conformance.view.segments import Transmission

CHAR = 8.33e-3


def _plain_reply(t: Transmission) -> list[Event]:
    """Transmission.reply as the loop over every character worked it out (no contention)."""
    heard = t.heard
    text = len(heard) > 1 and heard[1].char7 == STX
    for i, e in enumerate(heard):
        if text and e.char7 == ETX:
            return heard[: i + 1]
        if not text and e.char7 == LF:
            return heard[: i + 1]
        if text and e.char7 == LF:
            nxt = heard[i + 1] if i + 1 < len(heard) else None
            if nxt is None or nxt.start - e.end > MULTILINE_GAP_MAX + TOLERANCE:
                return heard[: i + 1]
    return list(heard)


def _plain_framed(t: Transmission, heard: list[Event], policy: Policy) -> list[Event]:
    """rebuilt_records._framed as the loop over every gap worked it out."""
    if not heard or heard[0].start - t.end > policy.first_char_timeout:
        return []
    framed = t.reply
    for i in range(1, len(framed)):
        multiline_gap = framed[i - 1].char7 == 0x0A
        if not multiline_gap and framed[i].start - framed[i - 1].end > policy.reply_idle:
            return framed[:i]
    return framed


def _transmission(rng: random.Random, policy: Policy) -> Transmission:
    command = [
        Event(EventKind.CHAR, TOOL, i * CHAR, (i + 1) * CHAR, wire=to_wire_7e1(ord(c)))
        for i, c in enumerate("0M!")
    ]
    t = command[-1].end + rng.choice([0.009, 0.012])
    shape = rng.choice(["line", "line", "text", "no-lf", "two-lines"])
    body = {
        "line": "0+1.5+22\r\n",
        "text": f"0{chr(STX)}line one\r\nline two\r\n{chr(ETX)}",
        "no-lf": "0+1.5+22\r",
        "two-lines": "0+1\r\n0\r\n",
    }[shape]
    heard = []
    for c in body:
        wire = to_wire_7e1(ord(c))
        roll = rng.random()
        if roll < 0.05:
            wire ^= 0x80  # bad parity: the character bits are the same
        elif roll < 0.08:
            wire = 0x100 | ord(c)  # no byte: the loop's path
        if rng.random() < 0.15:
            t += rng.choice([policy.reply_idle * 2, policy.reply_idle, 0.2, math.nan])
        heard.append(Event(EventKind.CHAR, DUT, t, t + CHAR, wire=wire))
        if not math.isnan(t):
            t += CHAR + rng.choice([0.0, 0.5e-3])
        else:
            t = heard[0].start + len(heard) * CHAR * 2
    return Transmission(None, command, heard)


@pytest.mark.parametrize("seed", range(40))
def test_reply_and_its_idle_cut_as_the_plain_loops_give(seed) -> None:
    rng = random.Random(seed)
    policy = Policy()
    for _ in range(25):
        t = _transmission(rng, policy)
        assert t.reply == _plain_reply(t)
        heard = [e for e in t.heard if e.start >= t.end]
        first = heard[0] if heard else None
        assert rebuilt_records._framed(t, first, policy) == _plain_framed(t, heard, policy)
        # the stimulus's attempt frames the characters heard after the command (matrix14:
        # the first of them found, not all of them listed)
        attempt = rebuilt_records._attempt(t, t.command, False, None, policy, 0.0)
        assert attempt.reply_events == _plain_framed(t, heard, policy)


def test_the_shapes_are_covered() -> None:
    """The replies above take every way out of the loops: cut at the first LF, kept whole
    (no LF), cut at a gap over the idle, not cut at one after an LF."""
    policy = Policy()
    seen = set()
    for seed in range(40):
        rng = random.Random(seed)
        for _ in range(25):
            t = _transmission(rng, policy)
            reply = t.reply
            heard = [e for e in t.heard if e.start >= t.end]
            framed = rebuilt_records._framed(t, heard[0] if heard else None, policy)
            seen.add("cut at LF" if len(reply) < len(t.heard) else "whole")
            if framed and len(framed) < len(reply):
                seen.add("cut at idle")
            if any(isinstance(e.wire, int) and e.wire > 0xFF for e in t.heard):
                seen.add("no byte")
    assert seen >= {"cut at LF", "whole", "cut at idle", "no byte"}


@pytest.mark.parametrize("late", [False, True])
def test_the_attempt_frames_what_came_after_the_command(late) -> None:
    """A character heard while the command went out (contention) is not the reply's first:
    the attempt frames the characters heard after the command ended, as when it listed them
    all (matrix14: the first of them is found instead); their first past the first-character
    timeout is no reply, however soon the early one came."""
    policy = Policy()
    command = [
        Event(EventKind.CHAR, TOOL, i * CHAR, (i + 1) * CHAR, wire=to_wire_7e1(ord(c)))
        for i, c in enumerate("0M!")
    ]
    early = Event(EventKind.CHAR, DUT, CHAR, 2 * CHAR, wire=to_wire_7e1(ord("0")))
    start = command[-1].end + (policy.first_char_timeout + 0.005 if late else 0.009)
    reply = [
        Event(EventKind.CHAR, DUT, start + i * CHAR, start + (i + 1) * CHAR, to_wire_7e1(ord(c)))
        for i, c in enumerate("00011\r\n")
    ]
    t = Transmission(None, command, [early, *reply])
    attempt = rebuilt_records._attempt(t, t.command, False, None, policy, 0.0)
    assert attempt.reply_events == _plain_framed(t, reply, policy) == ([] if late else reply)
    assert attempt.stray_events == [early] and not attempt.ok
