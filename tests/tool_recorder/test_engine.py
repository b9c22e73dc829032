"""The tool recorder's engine: break rules, wire timing, retries and bounded reads (section 7)."""

from __future__ import annotations

import pytest

from conformance.protocol import commands as cmds
from conformance.protocol.timing import (
    BREAK_MIN,
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    MARKING_AFTER_BREAK,
    NO_BREAK_WINDOW,
    RETRY_AFTER_BREAK,
    RETRY_MAX,
    RETRY_MIN,
    TOLERANCE,
)
from conformance.tool_recorder.policy import Policy
from conformance.tool_recorder.records import NO_REPLY, OK, TOO_LONG
from tests.support.own_time import own_time
from tests.tool_recorder.test_scripted_sensor import (
    Babbler,
    Burst,
    ScriptedSensor,
    rig,
    tool_breaks,
    with_crc,
)

ACK = {"0!": ["0\r\n"], "1!": ["1\r\n"], "0I!": ["013VENDOR__MODEL_001\r\n"]}


def two_sensors():
    return ScriptedSensor(ACK, "0"), ScriptedSensor(ACK, "1")


# -- break rules (R-7.0-17, R-7.1-01) ----------------------------------------------------------
def test_first_command_gets_break_follow_up_within_87_ms_does_not():
    master, _ = rig(ScriptedSensor(ACK))
    first = master.acknowledge()
    follow = master.identify()
    assert first.ok and follow.ok
    assert first.last.break_event is not None
    assert follow.last.break_event is None
    idle = follow.last.command_events[0].start - first.reply_events[-1].end
    assert idle < NO_BREAK_WINDOW


def test_break_after_more_than_87_ms_of_marking():
    master, _ = rig(ScriptedSensor(ACK))
    master.acknowledge()
    master.link.wait(0.088)
    near = master.acknowledge()  # 88 ms of marking since the reply's LF: window exceeded
    master.link.wait(0.060)
    inside = master.acknowledge()  # 60 ms: inside the window
    assert near.last.break_event is not None
    assert inside.last.break_event is None


def test_break_on_new_address_even_right_after_a_reply():
    master, _ = rig(*two_sensors())
    master.acknowledge("0")
    other = master.acknowledge("1")
    back = master.acknowledge("0")
    assert other.ok and back.ok
    assert other.last.break_event is not None
    assert back.last.break_event is not None


def test_forced_break():
    master, _ = rig(ScriptedSensor(ACK))
    master.acknowledge()
    assert master.transact("0!", force_break=True).last.break_event is not None


def test_break_length_and_marking_before_first_start_bit_from_transcript():
    master, bus = rig(ScriptedSensor(ACK))
    master.acknowledge()
    master.link.wait(0.2)
    master.identify()
    breaks = tool_breaks(bus)
    assert len(breaks) == 2
    for brk in breaks:
        assert brk.duration >= BREAK_MIN + TOLERANCE  # R-7.0-02 with the tolerance as margin
        after = next(e for e in bus.transcript if e.kind == "char" and e.start >= brk.end)
        assert after.origin == "tool"
        assert after.start - brk.end >= MARKING_AFTER_BREAK  # R-7.0-06


def test_command_characters_back_to_back_7e1():
    master, _ = rig(ScriptedSensor(ACK))
    ex = master.identify()
    sent = ex.last.command_events
    assert "".join(chr(e.char7) for e in sent) == "0I!"
    assert all(e.parity_ok for e in sent)
    gaps = [b.start - a.end for a, b in zip(sent, sent[1:], strict=False)]
    assert all(0 <= g <= INTER_CHAR_GAP_MAX for g in gaps)  # R-7.0-13


def test_waits_for_dut_to_release_line_before_driving():
    master, _ = rig(ScriptedSensor(ACK))
    a = master.acknowledge()
    b = master.acknowledge()
    assert b.last.command_events[0].start - a.reply_events[-1].end >= 7.5e-3 + TOLERANCE


# -- retries (R-7.2-02..06) -------------------------------------------------------------------
# The second policy retries as early as allowed, so only the engine's deliberate push of the
# last retry past 100 ms after the break satisfies R-7.2-03.
@pytest.mark.parametrize("policy", [Policy(), Policy(first_char_timeout=20e-3, retry_gap=0.0)])
def test_silent_sensor_three_sequences_of_three_sends(policy):
    master, bus = rig(ScriptedSensor({}), policy=policy)
    ex = master.acknowledge()
    assert not ex.ok and not ex.answered
    assert [(a.sequence, a.retry) for a in ex.attempts] == [
        (s, r) for s in range(3) for r in range(3)
    ]
    assert all(a.reason == NO_REPLY for a in ex.attempts)
    for attempt in ex.attempts:
        assert (attempt.break_event is not None) == (attempt.retry == 0)
    for prev, cur in zip(ex.attempts, ex.attempts[1:], strict=False):
        if cur.retry == 0:
            continue
        delay = cur.command_events[0].start - prev.command_end
        assert RETRY_MIN <= delay <= RETRY_MAX  # R-7.2-02
    for seq in range(3):
        brk = ex.attempts[3 * seq].break_event
        retries = ex.attempts[3 * seq + 1 : 3 * seq + 3]
        assert any(r.command_events[0].start - brk.end > RETRY_AFTER_BREAK for r in retries)
    assert len(tool_breaks(bus)) == 3


def test_retries_false_sends_once():
    master, _ = rig(ScriptedSensor({}))
    ex = master.transact("0!", retries=False)
    assert len(ex.attempts) == 1 and ex.last.reason == NO_REPLY
    assert len(master.transact("0!", expect_reply=False).attempts) == 1


def test_sensor_that_wakes_late_answers_the_retry_after_100_ms():
    # Answers only commands that start more than 100 ms after the break: needs the late retry.
    state = {"break_end": 0.0}
    sensor = ScriptedSensor({})

    def script(text: str):
        heard_end = sensor.heard[-1][0]
        start = heard_end - 2 * CHAR_TIME
        return "0\r\n" if start - state["break_end"] > 0.1 else None

    sensor.script = script
    original = sensor.on_break

    def on_break(start, end):
        state["break_end"] = end
        original(start, end)

    sensor.on_break = on_break
    master, _ = rig(sensor)
    ex = master.acknowledge()
    assert ex.ok and len(ex.attempts) == 3 and ex.attempts[0].break_event is not None


def test_retry_on_bad_crc_waits_for_the_invalid_reply_to_finish():
    bad = "0+1.5" + "AAA" + "\r\n"
    script = {"0MC!": ["00001\r\n"], "0D0!": [bad, with_crc("0+1.5")]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0", crc=True))
    d0 = m.data[0]
    assert [a.reason.split(":")[0] for a in d0.attempts] == ["invalid", OK]
    assert "CRC" in d0.attempts[0].reason
    first, retry = d0.attempts
    assert retry.break_event is None
    assert retry.command_events[0].start > first.reply_events[-1].end  # R-7.2-06
    assert retry.command_events[0].start - first.command_end >= RETRY_MIN
    assert m.values == ["+1.5"]


def test_retry_on_bad_parity():
    script = {"0!": [Burst("0\r\n", bad_parity=(0,)), "0\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    ex = master.acknowledge()
    assert ex.ok and len(ex.attempts) == 2
    assert ex.attempts[0].reason == "invalid: parity error in character 1"


def test_retry_on_8_33_ms_marking_inside_reply_and_on_wrong_address():
    script = {"0!": [Burst("0\r\n", gap=10e-3), "1\r\n", "0\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    ex = master.acknowledge()
    assert ex.ok and len(ex.attempts) == 3
    assert "marking inside the reply" in ex.attempts[0].reason
    assert "address" in ex.attempts[1].reason


def test_golden_policy_ends_reply_after_8_33_ms_marking():
    script = {"0!": [Burst("0\r\n", gap=10e-3), "0\r\n"]}
    master, _ = rig(ScriptedSensor(script), policy=Policy.golden())
    ex = master.acknowledge()
    first = ex.attempts[0]
    assert first.reason == "idle" and len(first.reply_events) == 1
    assert first.end - first.reply_events[0].end == pytest.approx(CHAR_TIME + TOLERANCE)
    assert len(ex.attempts) > 1  # R-7.2-05: 8.33 ms of marking triggers a retry


def test_late_reply_is_recorded_not_missed():
    master, _ = rig(ScriptedSensor({"0!": [Burst("0\r\n", at=25e-3)]}))
    ex = master.transact("0!", retries=False)
    assert ex.ok
    assert ex.reply_events[0].start - ex.last.command_end == pytest.approx(25e-3)


# -- bounded reads ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("start", "first_reason"),
    [
        (0.15, TOO_LONG),  # starts after the command: a reply that never ends
        (0.05, "invalid: bus contention"),  # already talking: never the command's reply
    ],
)
def test_babbling_device_ends_bounded(start, first_reason):
    master, _ = rig(Babbler(10_000, start=start))
    with own_time() as took:  # less any wait for a CPU: a busy machine does not stretch it
        master.link.wait(0.1)
        ex = master.acknowledge()
    assert took.seconds < 5, took
    assert not ex.ok
    assert all(len(a.reply_events) <= master.policy.max_reply_chars for a in ex.attempts)
    assert ex.attempts[0].reason.startswith(first_reason)
    assert len(ex.attempts) == 9


def test_stray_chatter_before_command_is_not_taken_as_reply():
    sensor = ScriptedSensor(ACK)
    master, bus = rig(sensor, Babbler(3, start=0.0, char="z"))
    master.link.wait(0.5)
    ex = master.acknowledge()
    assert ex.ok and "".join(chr(e.char7) for e in ex.last.stray_events) == "zzz"


# -- raw probes -------------------------------------------------------------------------------
def test_raw_partial_command_with_gap_and_no_break():
    sensor = ScriptedSensor(ACK)
    master, _ = rig(sensor)
    master.acknowledge()
    ex = master.raw("0I!", gap=10e-3, break_first=False)
    sent = ex.last.command_events
    assert ex.last.break_event is None
    assert sent[1].start - sent[0].end == pytest.approx(10e-3)
    assert ex.command == cmds.identify("0")
    assert len(ex.attempts) == 1


def test_raw_malformed_and_wrong_parity():
    master, _ = rig(ScriptedSensor(ACK))
    ex = master.raw("0Q9!!")
    assert ex.command is None and ex.text == "0Q9!!" and ex.last.reason == NO_REPLY
    bad = master.raw(b"0!", parity=False)  # '0' = 0x30 has even weight, '!' = 0x21 too: fine
    assert all(e.parity_ok for e in bad.last.command_events)
    flipped = master.raw(bytes([0x30 | 0x80, 0x21]), parity=False)
    assert not flipped.last.command_events[0].parity_ok


def test_query_address_accepts_any_address():
    master, _ = rig(ScriptedSensor({"?!": ["7\r\n"]}, address="7"))
    ex = master.query_address()
    assert ex.ok and ex.reply_text == "7\r\n"


def test_change_address_follows_the_sensor():
    master, _ = rig(ScriptedSensor({"0A3!": ["3\r\n"]}))
    ex = master.change_address("3")
    assert ex.ok and master.address == "3"


# -- multi-line extended replies (4.4.13.1, decision A10) ---------------------------------------
def test_multiline_text_read_across_line_pauses_until_etx():
    line1 = Burst("0\x02First line.\r\n")
    line2 = Burst("Second line.\r\n\x03", at=line1.end_offset + 0.120)
    master, _ = rig(ScriptedSensor({"0XHELP!": [[line1, line2]]}))
    ex = master.transact("0XHELP!")
    assert ex.ok and len(ex.attempts) == 1
    assert ex.reply_text == "0\x02First line.\r\nSecond line.\r\n\x03"


def test_multiline_text_ends_when_next_line_is_over_150_ms_late():
    line1 = Burst("0\x02First line.\r\n")
    line2 = Burst("Late line.\r\n\x03", at=line1.end_offset + 0.200)
    master, _ = rig(
        ScriptedSensor({"0XHELP!": [[line1, line2]]}, break_cancels=False),
        policy=Policy.golden(),  # the recorder's 150 ms (an observer waits longer)
    )
    ex = master.transact("0XHELP!")
    assert ex.ok and ex.reply_text == "0\x02First line.\r\n"
    assert ex.end - ex.reply_events[-1].end >= 0.150


def test_stx_is_plain_garbage_for_non_extended_commands():
    master, _ = rig(ScriptedSensor({"0I!": ["0\x0213\r\n"]}))
    ex = master.transact("0I!", retries=False)
    assert ex.last.reason == "invalid: non-printable character in the reply"


def test_db_command_on_its_own_is_read_as_a_binary_packet():
    from conformance.protocol.binary import DataType, build_packet

    packet = build_packet("0", DataType.INT8, [-1, -2])
    master, _ = rig(ScriptedSensor({"0DB0!": [packet]}))
    ex = master.transact("0DB0!")
    assert ex.binary and ex.ok and ex.reply_bytes == packet


def test_the_last_dut_character_is_read_on_and_again_after_an_insertion():
    """The engine asks before every transmission where the DUT's last character ended; it
    reads the transcript on from where it stopped, and all again when an event went in
    before that (a served line keeps its transcript in start order)."""
    from conformance.tool_recorder.engine import _LastDutChar
    from conformance.transcript import DUT, TOOL, Event, EventKind

    def char(origin: str, start: float) -> Event:
        return Event(EventKind.CHAR, origin, start, start + 0.008, wire=0x30)

    events = [char(TOOL, 0.0), char(DUT, 0.02)]
    last = _LastDutChar()
    assert last.after(events) == pytest.approx(0.028)
    events += [char(TOOL, 0.05), Event(EventKind.NOTE, TOOL, 0.06, 0.06, text="note")]
    assert last.after(events) == pytest.approx(0.028)  # nothing of the DUT's since
    events.append(char(DUT, 0.1))
    assert last.after(events) == pytest.approx(0.108)
    events.insert(1, char(DUT, 0.01))  # earlier in the list: the last by position stands
    events.append(char(TOOL, 0.2))
    assert last.after(events) == pytest.approx(0.108)
    assert _LastDutChar().after([char(TOOL, 0.0)]) == float("-inf")
