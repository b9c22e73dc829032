"""Framing from CR LF (issue 18, part 9): a reply ends at its protocol end, never at a gap; a
gap is evidence for R-7.0-12 only, undecided on tainted stamps; the tool's own echoed
characters, and the DUT's that met them, never count as the DUT's reply text."""

from __future__ import annotations

import time
from dataclasses import replace

import pytest

from conformance.judges import wire
from conformance.judges.timing import StampUncertainty
from conformance.links.echo import EchoMode, EchoTracker, Expected
from conformance.links.factory import open_real_link
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import COLLISION, DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.segments import read_view

GAP = 60e-3  # s: longer than the old 50 ms run gap, so the old cut split the reply here


def _chars(origin: str, text: str, start: float, gap_after: dict[int, float] | None = None):
    out, t = [], start
    for k, c in enumerate(text):
        out.append(Event(EventKind.CHAR, origin, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
        t += CHAR_TIME + (gap_after or {}).get(k, 0.0)
    return out


def _gapped_reply(reply: str = "0+1.23+4.56\r\n", at: int = 5) -> tuple[list[Event], float]:
    """``0D0!`` and its reply with :data:`GAP` of marking after character ``at``; returns the
    events and where the gap starts."""
    cmd = _chars(TOOL, "0D0!", 0.0)
    start = cmd[-1].end + 10e-3
    rep = _chars(DUT, reply, start, {at: GAP})
    return cmd + rep, rep[at].end


def _verdicts(findings):
    return {f.requirement: f for f in findings}


def _tainted_near(at: float, u: float = 65e-3) -> StampUncertainty:
    """Stamps the link saw irregular (a batch, a lagging reader) around ``at``."""
    return StampUncertainty(0.5e-3, lambda s, e: u if s <= at + GAP and e >= at else 0.0)


def test_a_reply_with_a_gap_on_tainted_stamps_is_one_reply_and_the_gap_is_undecided():
    events, gap_at = _gapped_reply()
    stamps = _tainted_near(gap_at)
    (seg,) = wire.segments(events)
    assert "".join(chr(e.char7) for e in seg.reply) == "0+1.23+4.56\r\n"
    assert seg.later == []
    framing = _verdicts(wire.judge_framing([seg], stamps))
    assert framing["R-4.2-03"].verdict is Verdict.PASS
    assert framing["R-4.3-01"].verdict is Verdict.PASS
    gaps = _verdicts(wire.judge_gaps([seg], stamps))["R-7.0-12"]
    assert gaps.verdict is not Verdict.FAIL
    assert "set aside" in gaps.detail


def test_a_real_gap_inside_a_reply_fails_the_gap_rule_only():
    """On exact stamps the same gap is the DUT's: R-7.0-12 FAILs (the old cut never measured
    it, and blamed the framing), while the reply's framing conforms."""
    events, _ = _gapped_reply()
    segs = wire.segments(events)
    assert _verdicts(wire.judge_gaps(segs, 0.0))["R-7.0-12"].verdict is Verdict.FAIL
    framing = _verdicts(wire.judge_framing(segs, 0.0))
    assert framing["R-4.2-03"].verdict is Verdict.PASS
    assert framing["R-4.3-01"].verdict is Verdict.PASS


def test_a_service_request_split_by_tainted_stamps_is_one_frame():
    cmd = _chars(TOOL, "0M!", 0.0)
    ack = _chars(DUT, "00012\r\n", cmd[-1].end + 10e-3)
    sr = _chars(DUT, "0\r\n", ack[-1].end + 2.0, {0: GAP})
    stamps = _tainted_near(sr[0].end)
    framing = _verdicts(wire.judge_framing(wire.segments(cmd + ack + sr), stamps))
    assert framing["R-4.2-03"].verdict is Verdict.PASS
    assert framing["R-4.3-01"].verdict is Verdict.PASS


def test_a_binary_reply_ends_at_its_packet_length_not_at_a_gap():
    cmd = _chars(TOOL, "0DB0!", 0.0)
    packet = bytes([ord("0"), 2, 0, 1, 0x34, 0x12, 0xAA, 0xBB])  # size 2: 8 bytes in all
    t, rep = cmd[-1].end + 10e-3, []
    for k, b in enumerate(packet):
        rep.append(Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, wire=b))
        t += CHAR_TIME + (GAP if k == 3 else 0.0)
    extra = _chars(DUT, "0\r\n", t + 5e-3)
    (seg,) = wire.segments(cmd + rep + extra)
    assert seg.reply == rep and seg.reply_ended
    assert seg.later == extra


# -- echoes ---------------------------------------------------------------------------------
def _wire(text: str) -> list[int]:
    return [to_wire_7e1(ord(c)) for c in text]


def _expect(text: str) -> list[Expected]:
    return [Expected(b, CHAR_TIME) for b in _wire(text)]


def test_the_dut_s_late_bytes_before_an_echo_stay_the_dut_s():
    """Behind a USB latency timer the end of a reply and the echo of the next command come in
    one batch: the reply's bytes are the DUT's, the echo the tool's, no collision (the old
    sorting took the reply's bytes for differing echoes, then the echo for the DUT's)."""
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect(_expect("0D1!"))
    got = []
    for k, b in enumerate(_wire("14.250\r\n") + _wire("0D1!")):
        got += tracker.heard(b, k * CHAR_TIME)
    assert [(h.origin, chr(h.byte & 0x7F)) for h in got] == [
        *(("dut", c) for c in "14.250\r\n"),
        *(("tool", c) for c in "0D1!"),
    ]
    assert tracker.collisions == 0 and tracker.pending == 0
    assert not any(h.collided for h in got)


def test_the_dut_s_bytes_between_echoes_are_collisions_never_echoes():
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect(_expect("0D0!"))
    got = []
    for k, b in enumerate(_wire("00D\r0\n!")):  # the tool's 0D0! and the DUT's 0<CR><LF>
        got += tracker.heard(b, k * CHAR_TIME)
    tool = "".join(chr(h.byte & 0x7F) for h in got if h.origin == "tool")
    dut = [(chr(h.byte & 0x7F), h.collided) for h in got if h.origin == "dut"]
    assert tool == "0D0!"
    assert dut == [("0", True), ("\r", True), ("\n", True)]  # one 0 of the two is the tool's
    assert tracker.collisions == 3


@pytest.fixture
def echoing_link():
    """loop:// is an interface that hears itself: what the tool writes comes back."""
    link = open_real_link("loop://", echo=EchoMode.ON)
    try:
        yield link
    finally:
        link.close()


def _write_with_dut(link, dut_interleaved: bytes, wire_bytes: bytes) -> list[Event]:
    """The tool writes ``wire_bytes`` while the DUT's bytes meet them on the line: the loop
    returns ``dut_interleaved``, the tool's bytes and the DUT's in line order."""
    original = link._port_write
    link._port_write = lambda data: original(dut_interleaved)
    try:
        return link.write(wire_bytes)
    finally:
        link._port_write = original


def test_behind_echo_a_dut_talking_over_the_command_is_contention_not_a_reply(echoing_link):
    """A measurement the break did not abort: its service request meets the tool's next
    command on an echoing line. The DUT's bytes are contention (marked, never read as a
    reply), the tool's echo is its command, and the reply framing holds no FAIL."""
    link = echoing_link
    line = bytes(_wire("00D\r0\n!"))  # 0D0! with the DUT's 0<CR><LF> between its characters
    sent = _write_with_dut(link, line, bytes(_wire("0D0!")))
    assert "".join(chr(e.char7) for e in sent) == "0D0!"
    time.sleep(2 * CHAR_TIME)
    assert link.receive(link.now()) == []  # the collided bytes are no reply to read
    link.port.write(bytes(_wire("0+1.5\r\n")))  # the DUT's reply to 0D0!
    reply = link.receive(link.now() + 1.0, until=lambda got: len(got) == 7)
    assert sorted(chr(e.char7) for e in reply) == sorted("0+1.5\r\n")
    # loop:// hands bytes over faster than a wire: stamp them as a 1200 baud line would, in
    # the order the link recorded them, to read the view
    recorded = [e for e in link.transcript.events if e.kind is EventKind.CHAR]
    events = [
        replace(e, start=k * CHAR_TIME, end=(k + 1) * CHAR_TIME) for k, e in enumerate(recorded)
    ]
    collided = [e for e in events if e.origin == DUT and e.text == COLLISION]
    assert "".join(chr(e.char7) for e in collided) == "0\r\n"
    view = read_view(events)
    (t,) = view.commands
    assert t.text == "0D0!" and t.contention  # two talkers, said
    assert {id(e) for e in t.contention} <= {id(e) for e in collided}
    assert "".join(chr(e.char7) for e in t.reply) == "0+1.5\r\n"
    framing = wire.judge_framing(wire.segments(events), 0.0)
    assert not [f for f in framing if f.verdict is Verdict.FAIL], framing


def test_the_tail_of_a_frame_that_met_the_command_is_no_reply():
    """A service request that began during ``0D!`` and ended after it (the simulated bus
    queues its next characters behind the tool's): '<CR><LF>' is contention, not a reply to
    ``0D!`` (before: R-4.2-03/R-4.3-01 FAIL and a 0 ms R-7.0-09 FAIL on quick-ready)."""
    cmd = _chars(TOOL, "0D", 0.0)
    sr0 = _chars(DUT, "0", cmd[-1].end)  # the sensor's service request starts
    bang = _chars(TOOL, "!", sr0[0].end)
    tail = _chars(DUT, "\r\n", bang[0].end)  # queued behind the tool's '!'
    reply = _chars(DUT, "0+1\r\n", tail[-1].end + 9e-3)
    (t,) = read_view(cmd + sr0 + bang + tail + reply).transmissions
    assert [chr(e.char7) for e in t.contention] == ["0", "\r", "\n"]
    assert "".join(chr(e.char7) for e in t.reply) == "0+1\r\n"
    (seg,) = wire.segments(cmd + sr0 + bang + tail + reply)
    assert len(seg.contention) == 3 and seg.reply[0] is reply[0]


def test_the_tail_of_a_frame_the_command_cut_into_is_no_reply():
    """A late reply that began at the end of the tool's retry break, its characters back to
    back, cut by the retried command after the break's marking (the line queues the rest behind
    the command, as the Arduino kit and the simulated bus do): the rest is that reply's tail,
    not a reply begun 0 ms after the command (before: a 0.00 ms R-7.0-09 FAIL on the outside
    Due sensor of tests/e2e/test_outside_sensors.py). The tool's recorder reads it so live."""
    first = _chars(TOOL, "0D0!", 0.0)
    brk = Event(EventKind.BREAK, TOOL, first[-1].end + 30e-3, first[-1].end + 43e-3)
    head = _chars(DUT, "0+", brk.end)  # the late reply to the first 0D0!
    retry = _chars(TOOL, "0D0!", head[-1].end)  # back to back with it: it was still going
    tail = _chars(DUT, "1.5\r\n", retry[-1].end)
    events = [*first, brk, *head, *retry, *tail]
    _, t = read_view(events).transmissions
    assert t.cut is head[-1]
    assert t.reply == [] and [e.char7 for e in t.contention] == [e.char7 for e in tail]
    seg = wire.segments(events)[1]
    assert seg.reply == [] and len(seg.contention) == len(tail)
    # a reply after a frame that had ended (its LF came) is the command's, as before
    done = _chars(DUT, "0+2\r\n", brk.end)
    again = _chars(TOOL, "0D0!", done[-1].end)
    reply = _chars(DUT, "0+1.5\r\n", again[-1].end + 9e-3)
    _, t = read_view([*first, brk, *done, *again, *reply]).transmissions
    assert t.cut is None and t.reply == reply


@pytest.mark.parametrize("profile", ["quick-ready", "prompt-sr"])
def test_a_sensor_whose_service_request_comes_early_draws_no_fail(profile, tmp_path):
    """Both legal profiles send their service request long before ttt; whatever the tool's
    next command meets, no FAIL rests on it (quick-ready FAILed R-4.2-03, R-4.3-01 and
    R-7.0-09 on collided service requests before)."""
    import json
    import subprocess
    import sys

    out = tmp_path / "r"
    subprocess.run(
        [sys.executable, "-m", "conformance.cli", "--port", f"sim://?profile={profile}",
         "--report-dir", str(out)],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    data = json.loads((out / "verdicts.json").read_text())
    bad = {r["id"]: r["verdict"] for r in data["requirements"] if r["verdict"] == "FAIL"}
    assert not bad, bad


def test_a_reply_after_a_cut_collided_frame_is_kept_on_an_uncertain_link():
    """A collided frame whose LF was lost: the genuine reply that starts 9 ms after the
    command is not taken for its tail on a ±5 ms link (the allowance once added both stamps'
    uncertainty, 12.06 ms, and swallowed it); the view and the tool's recorder use one rule."""
    u = 5e-3

    def unsure(events):
        return [replace(e, uncertainty=u) for e in events]

    cmd = unsure(_chars(TOOL, "0D", 0.0))
    sr = unsure(_chars(DUT, "0\r", cmd[-1].end - 2 * CHAR_TIME))  # its LF never came
    bang = unsure(_chars(TOOL, "!", cmd[-1].end))
    reply = unsure(_chars(DUT, "0+1\r\n", bang[0].end + 9e-3))
    (t,) = read_view(cmd + sr + bang + reply).transmissions
    assert "".join(chr(e.char7) for e in t.reply) == "0+1\r\n"
    assert [chr(e.char7) for e in t.contention] == ["0", "\r"]


def _framing_after_foreign_identify(request: str) -> Verdict:
    """R-4.3-01 over 0C!, then zI! answered for 'z', then the unsolicited ``request``."""
    start = _chars(TOOL, "0C!", 0.0)
    ack = _chars(DUT, "000320\r\n", start[-1].end + 10e-3)
    ident = _chars(TOOL, "zI!", ack[-1].end + 0.2)
    reply = _chars(DUT, "z14CONFORM EMU001100SN0001\r\n", ident[-1].end + 10e-3)
    sr = _chars(DUT, request, reply[-1].end + 1.9)
    segs = wire.segments(start + ack + ident + reply + sr)
    return _verdicts(wire.judge_framing(segs, 0.0))["R-4.3-01"].verdict


@pytest.mark.parametrize(
    ("line", "expected"),
    [("0\r\n", Verdict.PASS), ("z\r\n", Verdict.PASS), ("1\r\n", Verdict.FAIL)],
)
def test_a_service_request_after_a_reply_for_another_address(line, expected):
    """R-4.3-01 (seed 4141, answers-foreign-address + concurrent-service-request): aC!'s
    service request '0' came 1.9 s after the sensor answered zI! for 'z', and was judged
    against 'z', the last reply's address: FAIL x3. A line sent unasked may carry the address
    of the measurement it belongs to, the last one started; any other address still FAILs."""
    assert _framing_after_foreign_identify(line) is expected


def _framing_of(exchanges: list[tuple[str, str]], own: str | None) -> Verdict:
    """R-4.3-01 over commands and their replies, 100 ms apart, judged with ``own``."""
    events, at = [], 0.0
    for command, reply in exchanges:
        sent = _chars(TOOL, command, at)
        heard = _chars(DUT, reply, sent[-1].end + 1.5e-3)
        events += sent + heard
        at = heard[-1].end + 0.1
    return _verdicts(wire.judge_framing(wire.segments(events), 0.0, own=own))["R-4.3-01"].verdict


def test_a_reply_with_the_sensors_own_address_after_another_address_is_its_address_first():
    """Sixteenth round: the lagopus sketch at '5' answered, 1.5 ms after the tool's '0!'
    (sent while the tool still assumed '0'), the ?!s it had kept while booting: '5<CR><LF>'
    has the responding sensor's address first. Judged without the sensor's address the
    reply is read against the command's, as before."""
    late = [("0!", "5\r\n"), ("5I!", "514UOSLOGEOLAGOPU000\r\n")]
    assert _framing_of(late, own="5") is Verdict.PASS
    assert _framing_of(late, own=None) is Verdict.FAIL


def test_a_sensor_shown_at_an_address_is_judged_there_not_at_its_own():
    """Once a reply began with its command's address ('9!' answered '9'), that address is the
    sensor's: '9!' answered with its first address '0' still FAILs R-4.3-01."""
    moved = [("9!", "9\r\n"), ("9!", "0\r\n")]
    assert _framing_of(moved, own="0") is Verdict.FAIL


def test_a_command_sent_again_at_its_bang_is_a_new_transmission():
    """The nineteenth round's logger (lixpaulian/dacq's sdi12_dr) behind an echoing
    interface reads its own echo as an invalid reply and sends the command again at once:
    ``0M!0M!0M!`` back to back. Read as one transmission, the retries were not seen: R-7.2-01
    FAILed "sent again only after a new break (a new sequence, not a retry)" on a recorder
    that retried 0 ms after each '!' (R-7.2-02's FAIL). The command's address right after its
    '!' starts the next transmission; '0M!!' and '0M!<CR><LF>' stay one (R-4.4-04 sees them)."""
    texts = [t.text for t in read_view(_chars(TOOL, "0M!0M!0M!", 0.0)).transmissions]
    assert texts == ["0M!", "0M!", "0M!"]
    assert [t.text for t in read_view(_chars(TOOL, "0M!!", 0.0)).transmissions] == ["0M!!"]
    crlf = read_view(_chars(TOOL, "0M!\r\n", 0.0)).transmissions
    assert [t.text for t in crlf] == ["0M!\r\n"]
    # another address at once is the next command too (below)
    split = read_view(_chars(TOOL, "0M!1M!", 0.0)).transmissions
    assert [t.text for t in split] == ["0M!", "1M!"]


def test_another_address_right_after_a_bang_is_the_next_command():
    """A command ends at its '!' (4.4, R-4.4-04), so an address (or the '?' of '?!') right
    after it begins the next command, whatever the sensor it names: a recorder that sends
    ``0M!`` and at once ``1M!`` addressed a new sensor with no break (R-7.0-17's FAIL). Read
    as one transmission, '0M!1M!' FAILed R-4.4-04 ("'!' is not exactly the last character")
    and R-7.0-17 saw no command without a break. What cannot begin a command stays part of
    the one before: '0M!$' (R-4.4-04 still sees it), '0M!!', '0M!<CR><LF>'."""
    for text, cut in [
        ("0M!1M!", ["0M!", "1M!"]),
        ("0M!a!", ["0M!", "a!"]),
        ("0M!?!", ["0M!", "?!"]),
        ("0M!1M!2D0!", ["0M!", "1M!", "2D0!"]),
        ("0M!$", ["0M!$"]),
    ]:
        assert [t.text for t in read_view(_chars(TOOL, text, 0.0)).transmissions] == cut, text
    # a few ms of marking between them (less than a new command's 7.93 ms): the same cut
    gapped = _chars(TOOL, "0M!", 0.0) + _chars(TOOL, "1M!", 3 * CHAR_TIME + 0.004)
    assert [t.text for t in read_view(gapped).transmissions] == ["0M!", "1M!"]
