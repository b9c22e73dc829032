"""Multi-line text a command talked over (truth12): the replies-after-retry sensor answered
0XHELP! 80 ms late, its first line '0<STX>CONFORM ...<CR><LF>' met the tool's retry (set
aside as contention) and its other lines came after the retry. They were framed as lines sent
unasked: R-4.2-02/-03 and R-4.3-01 FAILed "later, after 0XHELP!: reply '<ETX>'" and R-7.0-12
the 6.67 ms between two of its lines. The rest of such text is not framed (INCONCLUSIVE) and
its line gaps are R-4.4.13.1-03's; lines after single-line text that met a command are still
framed."""

from __future__ import annotations

from conformance.judges import wire
from conformance.transcript import DUT, TOOL
from conformance.verdicts import Verdict
from conformance.view.runs import Segment
from tests.support.hand_events import chars

LINE_GAP = 6.667e-3  # the emulator's pause between lines of multi-line text


def _talked_over(first_line: str, rest: list[str]) -> Segment:
    """0XHELP! whose first three characters met ``first_line`` (already under way), the
    other ``rest`` lines after it, each ``LINE_GAP`` after the one before."""
    command = chars(TOOL, "0XHELP!", 0.0)
    met = chars(DUT, first_line, command[3].start)
    later, at = [], max(command[-1].end, met[-1].end) + LINE_GAP
    for line in rest:
        later += chars(DUT, line, at)
        at = later[-1].end + LINE_GAP
    return Segment(None, command, later=later, contention=met, text="0XHELP!")


def _by_rule(findings):
    return {f.requirement: f for f in findings}


def test_r_4_2_02_03_r_4_3_01_rest_of_talked_over_multiline_text_is_not_framed() -> None:
    seg = _talked_over("0\x02CONFORM EMU001\r\n", ["aXSN! serial\r\n", "Measurements: M\r\n\x03"])
    assert wire.talked_through(seg)
    found = _by_rule(wire.judge_framing([seg], 0.0, own="0"))
    for rid in ("R-4.2-02", "R-4.2-03", "R-4.3-01"):
        assert found[rid].verdict is Verdict.INCONCLUSIVE, (rid, found[rid].detail)
        assert "rest of multi-line text" in found[rid].detail
    assert found["R-4.1-02"].verdict is Verdict.PASS  # parity is the sensor's own still


def test_r_7_0_12_line_gaps_of_talked_over_multiline_text_are_no_character_gaps() -> None:
    seg = _talked_over("0\x02CONFORM EMU001\r\n", ["aXSN! serial\r\n", "Measurements: M\r\n\x03"])
    gaps = wire.judge_gaps([seg], 0.0)[0]
    assert gaps.verdict is Verdict.PASS, gaps.detail


def test_lines_after_single_line_text_that_met_a_command_are_still_framed() -> None:
    """Not multi-line text (no STX second): what came after is framed as before, and its
    non-printable ETX still FAILs R-4.2-02."""
    seg = _talked_over("0+1.5\r\n", ["\x03"])
    assert not wire.talked_through(seg)
    found = _by_rule(wire.judge_framing([seg], 0.0, own="0"))
    assert found["R-4.2-02"].verdict is Verdict.FAIL
    assert found["R-4.2-03"].verdict is Verdict.FAIL


def test_multiline_text_ended_inside_the_command_leaves_later_lines_framed() -> None:
    """Its ETX met the command too: what follows is no rest of it."""
    seg = _talked_over("0\x02A\r\n\x03", ["\x03"])
    assert not wire.talked_through(seg)
    assert _by_rule(wire.judge_framing([seg], 0.0, own="0"))["R-4.2-02"].verdict is Verdict.FAIL


def _next_retry(first: Segment, line: str, rest: str, *, met: bool) -> Segment:
    """The next 0XHELP! after ``first``; ``line`` meets it (``met``) or comes after it."""
    command = chars(TOOL, "0XHELP!", first.later[-1].end + 0.055)
    heard = chars(DUT, line, command[3].start if met else command[-1].end + 0.1)
    later = chars(DUT, rest, heard[-1].end + LINE_GAP)
    if met:
        return Segment(None, command, later=later, contention=heard, text="0XHELP!")
    return Segment(None, command, later=heard + later, text="0XHELP!")


def test_r_4_2_02_text_talked_over_by_two_retries_is_not_framed() -> None:
    """multiline-long-line + replies-after-retry (seeds 4500..): the 80-character line met
    the next retry and the ETX came after it, framed alone: R-4.2-02/-03, R-4.3-01 FAILed."""
    first = _talked_over("0\x02CONFORM EMU001\r\n", ["aXSN! serial\r\n"])
    second = _next_retry(first, "L" * 80 + "\r\n", "\x03", met=True)
    found = _by_rule(wire.judge_framing([first, second], 0.0, own="0"))
    for rid in ("R-4.2-02", "R-4.2-03", "R-4.3-01"):
        assert found[rid].verdict is Verdict.INCONCLUSIVE, (rid, found[rid].detail)


def test_r_4_2_02_an_etx_after_a_command_no_text_met_is_framed() -> None:
    first = _talked_over("0\x02CONFORM EMU001\r\n", ["aXSN! serial\r\n"])
    second = _next_retry(first, "L\r\n", "\x03", met=False)
    assert _by_rule(wire.judge_framing([first, second], 0.0, own="0"))["R-4.2-02"].verdict is (
        Verdict.FAIL
    )


def _slow_second_line(first_line_end: str) -> list[Segment]:
    """0XHELP! whose retry met the help text's first line (its end ``first_line_end`` after
    the command), then 0XHELP! unheard 55 ms later, then 0M1! 88 ms after that, whose listen
    hears the text's second line 200 ms after the first (the replies-after-retry sensor
    beside multiline-slow-lines)."""
    talked = _talked_over("0\x02CONFORM\r\n", [])
    rest = chars(DUT, first_line_end, talked.command_end + LINE_GAP)
    first = Segment(None, talked.command, later=rest, contention=talked.contention, text="0XHELP!")
    silent = chars(TOOL, "0XHELP!", rest[-1].end + 0.055)
    command = chars(TOOL, "0M1!", silent[-1].end + 0.088)
    line = chars(DUT, "aXSN! serial number\r\n", rest[-1].end + 0.2)
    return [
        first,
        Segment(None, silent, text="0XHELP!"),
        Segment(None, command, reply=line, text="0M1!"),
    ]


def test_r_4_3_01_slow_next_line_after_a_silent_retry_is_undecided() -> None:
    """multiline-slow-lines + replies-after-retry (truth21): the first line of 0XHELP!'s help
    text met the retry, the next 0XHELP! went unheard, and the second line, 200 ms after the
    first, came in 0M1!'s listen: R-4.3-01 FAILed "reply to 0M1!: reply 'aXSN! serial
    number; ...' starts with 'a', not the address '0'". Its address is undecided: a line
    of that text need not start with it."""
    found = _by_rule(wire.judge_framing(_slow_second_line("EMU001 x\r\n"), 0.0, own="0"))
    assert found["R-4.3-01"].verdict is Verdict.INCONCLUSIVE, found["R-4.3-01"].detail
    assert "next line of multi-line text" in found["R-4.3-01"].detail


def test_r_4_3_01_wrong_address_after_ended_text_still_fails() -> None:
    """The same wire with the text's ETX heard before the silent retry: the reply to 0M1!
    is the sensor's own, and starting with 'a' FAILs R-4.3-01."""
    segs = _slow_second_line("EMU001 x\r\n\x03")
    assert _by_rule(wire.judge_framing(segs, 0.0, own="0"))["R-4.3-01"].verdict is Verdict.FAIL
