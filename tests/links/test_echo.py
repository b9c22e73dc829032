"""Echo handling and the timing meter: the pure parts of the real-bench links."""

from __future__ import annotations

import pytest

from conformance.judges.timing import (
    StampUncertainty,
    combine_local,
    judge_window,
    recheck,
    undecide_after_late_line,
)
from conformance.links.echo import EchoMode, EchoTracker, Expected, is_spacing_echo
from conformance.links.meter import ECHO_FLOOR, TimingMeter
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import to_wire_7e1
from conformance.verdicts import Verdict

CMD = [to_wire_7e1(ord(c)) for c in "0I!"]


def chars(text: str) -> list[Expected]:
    return [Expected(to_wire_7e1(ord(c)), CHAR_TIME) for c in text]


def feed(tracker: EchoTracker, data: list[int], t0: float = 0.0) -> list[tuple[str, int]]:
    out = []
    for k, byte in enumerate(data):
        out += [(h.origin, h.byte) for h in tracker.heard(byte, t0 + k * CHAR_TIME)]
    return out


def test_auto_detects_an_echo_and_keeps_the_reply_as_the_dut_s():
    tracker = EchoTracker(EchoMode.AUTO)
    tracker.expect([Expected(None, 13e-3), *chars("0I!")])
    reply = [to_wire_7e1(ord(c)) for c in "0\r\n"]
    got = feed(tracker, [0x00, *CMD, *reply])
    assert tracker.decided and tracker.echoes
    assert got == [("tool", 0x00)] + [("tool", b) for b in CMD] + [("dut", b) for b in reply]


def test_auto_without_echo_gives_every_byte_to_the_dut_even_one_matching_the_command():
    """The reply to 0! starts with '0', like the command: a prefix match is not an echo."""
    tracker = EchoTracker(EchoMode.AUTO)
    tracker.expect(chars("0!"))
    reply = [to_wire_7e1(ord(c)) for c in "0\r\n"]
    got = feed(tracker, reply)
    assert tracker.decided and not tracker.echoes
    assert got == [("dut", b) for b in reply]


def test_auto_with_a_silent_line_decides_no_echo_when_the_time_is_over():
    tracker = EchoTracker(EchoMode.AUTO)
    tracker.expect(chars("0!"))
    notes = tracker.expire()
    assert tracker.decided and not tracker.echoes
    assert any("does not echo" in n for n in notes)


def test_a_differing_echo_is_a_collision_kept_as_the_dut_s_byte():
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect(chars("0M!"))
    heard = []
    for k, byte in enumerate([CMD[0], to_wire_7e1(ord("x")), CMD[2]]):
        heard += tracker.heard(byte, k * CHAR_TIME)
    assert tracker.collisions == 1
    tool = [h for h in heard if h.origin == "tool"]
    dut = [h for h in heard if h.origin == "dut"]
    assert [h.byte for h in tool] == [CMD[0], to_wire_7e1(ord("M")), CMD[2]]
    assert [h.byte for h in dut] == [to_wire_7e1(ord("x"))]
    assert "collision" in dut[0].note


def test_off_never_takes_a_byte_for_an_echo():
    tracker = EchoTracker(EchoMode.OFF)
    tracker.expect(chars("0I!"))
    assert feed(tracker, CMD) == [("dut", b) for b in CMD]


def test_missing_echo_is_reported():
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect(chars("0I!"))
    feed(tracker, CMD[:2])
    notes = tracker.expire()
    assert tracker.missing == 1 and any("not heard" in n for n in notes)


@pytest.mark.parametrize("byte", [0x00, 0x80, 0xE0, 0xFE])
def test_spacing_echoes_are_zero_prefix_bytes(byte):
    assert is_spacing_echo(byte)


@pytest.mark.parametrize("byte", [0x30, 0x21, 0xFF, 0x01])
def test_characters_are_not_spacing_echoes(byte):
    assert not is_spacing_echo(byte)


# -- the meter ---------------------------------------------------------------------------------
def test_meter_without_echo_keeps_its_declared_floor():
    meter = TimingMeter(5e-3, kernel_stamps=True)
    meter.reader_lag.add(20e-3, "kernel stamp")  # kernel stamps: the reader's lag is harmless
    assert meter.uncertainty() == 5e-3
    meter.kernel_stamps = False  # the reader's own stamps: its lag is the stamps' error
    assert meter.uncertainty() == 20e-3


def test_meter_with_echo_uses_the_measured_spread_and_sets_stalls_aside_locally():
    meter = TimingMeter(5e-3, echo=True)
    assert meter.uncertainty() == ECHO_FLOOR
    for k in range(40):
        meter.spread(k, k + 0.05, 0.8e-3, "echo")
    meter.spread(100.0, 100.05, 7e-3, "a stalled echo")
    assert meter.uncertainty() == pytest.approx(0.8e-3)  # the stall is not the path's jitter
    assert meter.between(50.0, 50.01) == pytest.approx(0.8e-3)
    assert meter.between(100.02, 100.03) == pytest.approx(7e-3)  # ...but it is there
    assert meter.observed() == pytest.approx(7e-3)


def test_meter_sets_no_spread_aside_as_a_stall_before_it_has_enough_of_them():
    """A calibrate probe's 16 echoes behind a 16 ms latency timer: one 7.7 ms spread among
    fifteen of 0 ms is that bench's jitter (the phase of the timer's tick), not a stall."""
    meter = TimingMeter(5e-3, echo=True)
    for k in range(15):
        meter.spread(k, k + 0.03, 0.0, "echo")
    meter.spread(20.0, 20.03, 7.7e-3, "echo across a tick")
    assert meter.uncertainty() == pytest.approx(7.7e-3)
    assert meter.between(3.0, 3.01) == pytest.approx(7.7e-3)


def test_meter_taints_widen_only_where_they_are():
    meter = TimingMeter(5e-3, echo=True)
    meter.taint(10.0, 10.02, 4e-3, "frames overlapped")
    assert meter.between(9.0, 9.5) == ECHO_FLOOR
    assert meter.between(10.01, 10.5) == 4e-3


def test_user_figure_widens_never_narrows():
    meter = TimingMeter(5e-3)
    meter.widen_to = 1e-3
    assert meter.uncertainty() == 5e-3
    meter.widen_to = 9e-3
    assert meter.uncertainty() == 9e-3


# -- judging with local uncertainty ------------------------------------------------------------
def test_combine_local_sets_aside_only_what_irregular_stamps_left_undecided():
    passed = judge_window("R-7.0-10", "start", 10e-3, 1e-3, high=15.4e-3)
    undecided = judge_window("R-7.0-10", "start", 14e-3, 3e-3, high=15.4e-3)
    failed = judge_window("R-7.0-10", "start", 25e-3, 3e-3, high=15.4e-3, evidence=["0!"])
    found = combine_local("R-7.0-10", [(passed, False), (undecided, True)], "reply")
    assert found.verdict is Verdict.PASS and "1 reply set aside" in found.detail
    found = combine_local("R-7.0-10", [(passed, False), (failed, True)], "reply", real_time=False)
    assert found.verdict is Verdict.FAIL  # a decided FAIL on an exact clock always counts
    found = combine_local("R-7.0-10", [(undecided, True)], "reply")
    assert found.verdict is Verdict.INCONCLUSIVE  # nothing left to rest a verdict on
    found = combine_local("R-7.0-10", [(undecided, False)], "reply")
    assert found.verdict is Verdict.INCONCLUSIVE  # undecided with the regular figure: stays


def test_one_isolated_deviation_on_a_real_time_link_is_not_a_fail():
    """A host stall can make one stamp late with no trace; two deviations are a FAIL."""
    passed = judge_window("R-7.0-12", "gap", 0.0, 1e-3, high=1.66e-3, tolerance=0.0)
    failed = judge_window(
        "R-7.0-12", "gap", 6e-3, 1e-3, high=1.66e-3, tolerance=0.0, evidence=["0I!"]
    )
    assert failed.verdict is Verdict.FAIL
    lone = combine_local("R-7.0-12", [(passed, False), (failed, False)], "gap")
    assert lone.verdict is Verdict.INCONCLUSIVE and "1 of 2 gaps deviate" in lone.detail
    twice = combine_local("R-7.0-12", [(passed, False), (failed, False), (failed, False)], "gap")
    assert twice.verdict is Verdict.FAIL
    only = combine_local("R-7.0-12", [(failed, False)], "gap")
    assert only.verdict is Verdict.FAIL  # nothing contradicts the one observation
    exact = combine_local("R-7.0-12", [(passed, False), (failed, False)], "gap", real_time=False)
    assert exact.verdict is Verdict.FAIL


def test_stamp_uncertainty_is_the_base_or_more():
    u = StampUncertainty(1e-3, lambda a, b: 5e-3 if a < 2 else 0.0)
    assert u.between(1, 3) == 5e-3 and u.between(3, 4) == 1e-3
    assert StampUncertainty(2e-3).between(0, 1) == 2e-3


def test_recheck_undoes_verdicts_a_larger_final_uncertainty_no_longer_supports():
    close = judge_window("R-7.0-10", "start", 14.5e-3, 0.5e-3, high=15.4e-3)
    far = judge_window("R-7.0-10", "start", 10e-3, 0.5e-3, high=15.4e-3)
    assert close.verdict is far.verdict is Verdict.PASS
    assert recheck([close, far], 2e-3) == 1
    assert close.verdict is Verdict.INCONCLUSIVE and far.verdict is Verdict.PASS
    assert "grew to ±2.00 ms" in close.detail


def test_a_served_line_that_fell_behind_leaves_no_fail_standing():
    """The recorder role on a line this tool serves in real time: when the host made the
    played sensors late, a FAIL may be the recorder's right reaction to a late sensor."""
    from conformance.verdicts import Finding

    failed = Finding("R-4.4.8-05", Verdict.FAIL, "stopped reading", observed=1, evidence=["0D0!"])
    warned = Finding("R-7.2-02", Verdict.WARN, "retried early", observed=1, evidence=["0M!"])
    passed = Finding("R-7.2-01", Verdict.PASS, "retried", observed=1)
    assert undecide_after_late_line([failed, warned, passed], 7.8e-3, 2e-3) == 2
    assert failed.verdict is warned.verdict is Verdict.INCONCLUSIVE
    assert passed.verdict is Verdict.PASS  # what the recorder did right stays right
    assert "fell 7.8 ms behind" in failed.detail


# -- a break's echo behind the DUT's bytes (truth25) -----------------------------------------
BREAK = Expected(None, 13e-3)


def test_a_break_echo_behind_the_dut_s_late_bytes_is_still_the_tool_s():
    """Under host stalls the rest of a late reply reached the host between the tool's break
    and the break's 0x00: the 0x00 was recorded as the DUT's, ahead of the next reply."""
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect([BREAK])
    late = [to_wire_7e1(ord(c)) for c in "5;\r\n"]
    assert feed(tracker, [*late, 0x00]) == [("dut", b) for b in late] + [("tool", 0x00)]
    tracker.expect(chars("0I!"))
    assert feed(tracker, CMD) == [("tool", b) for b in CMD]


def test_an_owed_break_echo_is_only_a_nul():
    """'@' with its parity (0xC0) reads like a short spacing pulse, and a reply's CRC may
    hold it: behind the DUT's bytes only the 0x00 a break makes is taken for its echo."""
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect([BREAK])
    crc = [to_wire_7e1(ord(c)) for c in "1@Jw"]
    assert crc[1] == 0xC0 and is_spacing_echo(0xC0)
    assert feed(tracker, crc) == [("dut", b) for b in crc]


def test_a_nul_after_the_command_s_echo_is_the_dut_s():
    """A real interface reads the line in wire order: a 0x00 after the echo of the command
    that followed the break is no echo of that break."""
    tracker = EchoTracker(EchoMode.ON)
    tracker.expect([BREAK])
    tracker.expect(chars("2I!"))
    two_i = [to_wire_7e1(ord(c)) for c in "2I!"]
    assert feed(tracker, [*two_i, 0x00]) == [("tool", b) for b in two_i] + [("dut", 0x00)]
