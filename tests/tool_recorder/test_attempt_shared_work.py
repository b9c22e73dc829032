"""Issue 22, matrix round 12: an attempt's fixed work done once. The engine frames every
reply of one kind under one policy with one frozen Framing (made once per policy object,
not per attempt; another policy takes effect at once), and whether a reply closes its
exchange reads its events' kinds in C: ``kind is CHAR`` for each, an equal string that is
no EventKind included, as the generator over them read it."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.protocol.commands import parse_command
from conformance.tool_recorder import engine as engine_module
from conformance.tool_recorder.engine import (
    ToolRecorder,
    _LastDutChar,
    closes_exchange,
    framing_for,
)
from conformance.tool_recorder.reply_end import Framing
from conformance.transcript import DUT, TOOL, Event, EventKind
from tests.support.hand_events import chars
from tests.tool_recorder.test_scripted_sensor import ScriptedSensor, rig


def _framings(master: ToolRecorder, monkeypatch: pytest.MonkeyPatch) -> list[Framing]:
    seen: list[Framing] = []
    listen = ToolRecorder._listen

    def kept(self, command_end, framing):  # noqa: ANN001, ANN202 - as ToolRecorder._listen
        seen.append(framing)
        return listen(self, command_end, framing)

    monkeypatch.setattr(ToolRecorder, "_listen", kept)
    return seen


def test_one_framing_per_policy_and_kind_of_reply(monkeypatch: pytest.MonkeyPatch) -> None:
    master, _ = rig(ScriptedSensor({"0!": ["0\r\n"] * 3, "0I!": ["014MAKER   MODEL 1.0\r\n"]}))
    seen = _framings(master, monkeypatch)
    master.transact("0!")
    master.transact("0I!")
    master.transact("0XSET!", retries=False)
    master.transact("0!")
    plain = framing_for(master.policy, False, False)
    assert seen[0] == plain and seen[1] is seen[0] and seen[3] is seen[0]
    assert seen[2] == framing_for(master.policy, False, True) and seen[2] is not seen[0]
    # another policy: its own framing at once, with its idle
    master.policy = replace(master.policy, reply_idle=0.02)
    master.transact("0!")
    assert seen[-1].idle == 0.02 and seen[-1] == framing_for(master.policy, False, False)


def test_framing_for_is_what_an_attempt_made_before() -> None:
    p = engine_module.Policy()
    for binary, multiline in ((False, False), (False, True), (True, False)):
        assert framing_for(p, binary, multiline) == Framing(
            idle=p.reply_idle,
            max_chars=p.max_binary_bytes if binary else p.max_reply_chars,
            binary=binary,
            multiline=multiline,
            max_text_chars=p.max_text_chars,
            line_wait=p.line_wait,
        )


def test_a_reply_closes_its_exchange_only_if_every_event_is_a_character() -> None:
    command = parse_command("0D0!")
    reply = chars(DUT, "0+1.5\r\n", 1.0)
    assert closes_exchange(command, reply)
    note = Event(EventKind.NOTE, DUT, 1.01, 1.01, text="x")
    assert not closes_exchange(command, [*reply[:3], note, *reply[3:]])
    brk = Event(EventKind.BREAK, DUT, 0.9, 0.95)
    assert not closes_exchange(command, [brk, *reply])
    # a kind equal to CHAR as a string but not the member: not read as one ("is", not "==")
    odd = replace(reply[0], kind="char")  # type: ignore[arg-type]
    assert odd.kind == EventKind.CHAR
    assert not closes_exchange(command, [odd, *reply[1:]])


class _Counted(list):
    """A transcript's events that count how many were read by index."""

    reads = 0

    def __getitem__(self, k):  # noqa: ANN001, ANN204 - list's own
        self.reads += 1
        return super().__getitem__(k)


def _forward(events: list[Event], end: float) -> float:  # the pass it replaced
    for e in events:
        if e.kind is EventKind.CHAR and e.origin != TOOL:
            end = e.end
    return end


def test_the_last_dut_character_is_found_from_the_end_as_the_forward_pass_found_it() -> None:
    import random

    rng = random.Random(22)
    for _ in range(200):
        events: _Counted = _Counted()
        last = _LastDutChar()
        end, seen = float("-inf"), 0
        for _batch in range(rng.randint(1, 6)):
            for _ in range(rng.randint(0, 12)):
                kind = rng.choice([EventKind.CHAR] * 4 + [EventKind.NOTE, EventKind.BREAK])
                origin = rng.choice([TOOL, DUT, "sensor 1"])
                t = rng.random()
                events.append(Event(kind, origin, t, t + rng.random() * 0.01, wire=0x30))
            end = _forward(events[seen:], end)
            seen = len(events)
            assert last.after(events) == end


def test_a_command_and_its_reply_are_looked_at_from_the_reply_s_end() -> None:
    events: _Counted = _Counted(chars(TOOL, "0IM_001!", 0.0))
    last = _LastDutChar()
    last.after(events)
    events += chars(DUT, "0,RH,%,relative humidity;\r\n", 0.08)
    events += chars(TOOL, "0I!", 0.5)
    lf_end = events[-4].end
    events.reads = 0
    assert last.after(events) == lf_end
    # the three command characters and the LF, and the two the read-on check reads (the
    # last seen and the last): not the 31 new ones
    assert events.reads <= 6
