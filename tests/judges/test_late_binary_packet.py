"""An aDBn! packet that came late is neither the next command's reply nor silence (truth18).

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then) sent
0DB999!'s empty packet into each retry, which the engine set aside as bus contention, and
the last try's packet 30 ms into the 0M! after it. Beside never-standby,
partial-command-accepted, stays-awake-after-foreign (and answers-foreign-address for the
first), R-5.2-06 FAILed "0DB999! returned '(nothing)'" and R-4.2-02/-03 FAILed "reply to
0M!: reply '0<0x00><0x00><0x00><0x0F><0x00>' contains non-printable characters". Each test
fails on the tree before (832cfdc); a packet the sensor sent in its window is still judged.
"""

from __future__ import annotations

from conformance.judges import wire
from conformance.judges.empty_packet import judge_empty_packets
from conformance.protocol import commands as cmds
from conformance.protocol.binary import DataType, build_packet, empty_packet
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

LATE = 0.080  # the sensor's reply start after the command it heard
EMPTY = empty_packet("0")  # address, size 0, type 0, CRC


def _packet_chars(data: bytes, start: float) -> list[Event]:
    """A binary packet's bytes as 8N1 characters (no parity bit), back to back."""
    events = chars(DUT, "".join(chr(b & 0x7F) for b in data), start)
    return [
        Event(e.kind, e.origin, e.start, e.end, wire=b) for e, b in zip(events, data, strict=True)
    ]


def _db_then_m(reply: list[Event] | None = None) -> list[Event]:
    """0DB999! unanswered at 0 s, 0M! 30 ms after it, and the DB packet 80 ms after
    0DB999! ended (``reply``: what the sensor sent instead)."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013)]
    events += (db := chars(TOOL, "0DB999!", 0.022))
    events += chars(TOOL, "0M!", db[-1].end + 0.030)
    events += reply if reply is not None else _packet_chars(EMPTY, 0.0)
    return sorted(events, key=lambda e: e.start)


def test_a_late_packet_taken_by_the_next_command_is_not_framed_as_its_reply() -> None:
    db_end = 0.022 + 7 * (1 / 120)
    packet = _packet_chars(EMPTY, db_end + LATE)
    found = {f.requirement: f for f in wire.judge_framing(segments(_db_then_m(packet)))}
    for rid in ("R-4.2-02", "R-4.2-03", "R-4.3-01"):
        assert found[rid].verdict is Verdict.INCONCLUSIVE, found[rid]  # FAIL before
        assert "may be 0DB999!'s late binary packet" in found[rid].detail


def test_a_bad_text_reply_after_an_unanswered_text_command_still_fails() -> None:
    """Only a binary command before makes the reply a packet: after an unanswered 0D0! the
    text framing rules hold whichever command the reply answers."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013)]
    events += (d := chars(TOOL, "0D0!", 0.022))
    events += chars(TOOL, "0M!", d[-1].end + 0.030)
    events += chars(DUT, "0+1\x01\r\n", d[-1].end + LATE)
    found = {f.requirement: f for f in wire.judge_framing(segments(events))}
    assert found["R-4.2-02"].verdict is Verdict.FAIL


def _probe(text: str, t: float, reply: bytes = b"", late: bytes = b"") -> Exchange:
    """``text`` tried three times from ``t``: ``reply`` taken in the first window, else
    unanswered, ``late`` met by the retry (kept as its stray characters)."""
    attempts = []
    for retry in range(3):
        sent = chars(TOOL, text, t)
        got = _packet_chars(reply, sent[-1].end + 0.009) if reply and retry == 0 else []
        stray = _packet_chars(late, t - 0.01) if late and retry == 1 else []
        reason = OK if got else NO_REPLY
        attempts.append(Attempt(None, sent, got, reason, sent[-1].end + 0.03, 0, retry, stray))
        if got:
            break
        t = sent[-1].end + 0.05
    return Exchange(cmds.parse_command(text), text, attempts, binary=True)


def test_r_5_2_06_a_probe_answered_into_its_retries_is_inconclusive() -> None:
    late = _probe("0DB999!", 0.0, late=EMPTY)
    found = judge_empty_packets([late], "0")
    assert found.verdict is Verdict.INCONCLUSIVE, found  # FAIL "returned '(nothing)'" before
    assert "answered only after the reply window" in found.detail


def test_r_5_2_06_a_silent_probe_or_a_wrong_packet_still_fails() -> None:
    assert judge_empty_packets([_probe("0DB999!", 0.0)], "0").verdict is Verdict.FAIL
    wrong = _probe("0DB5!", 0.0, reply=build_packet("0", DataType.INT8, [7]))
    late = _probe("0DB999!", 1.0, late=EMPTY)
    found = judge_empty_packets([wrong, late], "0")
    assert found.verdict is Verdict.FAIL and "0DB5!" in found.detail, found


def test_r_5_2_06_empty_packets_in_their_windows_pass() -> None:
    probes = [_probe(t, 0.0, reply=EMPTY) for t in ("0DB5!", "0DB999!")]
    assert judge_empty_packets(probes, "0").verdict is Verdict.PASS


def test_a_timely_reply_after_a_silent_adbn_is_the_command_s_own() -> None:
    """binary-no-empty-packet: 0DB999! went unanswered and the 0M! after it was answered in
    its window; that reply is 0M!'s, framed as ever (INCONCLUSIVE in the first try of this
    change, from the snapshot): a bad one still FAILs."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013)]
    events += (db := chars(TOOL, "0DB999!", 0.022))
    events += (m := chars(TOOL, "0M!", db[-1].end + 0.030))
    events += chars(DUT, "00\x0123\r\n", m[-1].end + 0.009)
    found = {f.requirement: f for f in wire.judge_framing(segments(events))}
    assert found["R-4.2-02"].verdict is Verdict.FAIL, found["R-4.2-02"]
