"""The recorder judges time characters with each character's own uncertainty, not only the
run's figure: a served line's characters read together with others (the kernel merged their
packets) may have been sent anywhere in the span before that read, and carry it
(``Event.uncertainty``; :func:`conformance.emulator_server.arrivals.char_doubt`). Judged with
the run's 5 ms alone, their made-up 0 ms gaps and late starts PASSed or FAILed."""

from __future__ import annotations

from dataclasses import replace

from conformance.judges.recorder.breaks import judge_break_rules, judge_breaks
from conformance.judges.recorder.commands import judge_character_gaps
from conformance.judges.recorder.retries import judge_retries
from conformance.transcript import TOOL, EventKind
from conformance.verdicts import Verdict
from conformance.view.segments import read_view

from .test_recorder_judges import Wire, by_id

U = 5e-3  # the served line's declared uncertainty on loopback


def doubted(wire: Wire, index: int, doubt: float) -> list:
    """``wire``'s events with the characters of the recorder's ``index``-th transmission (0:
    the first) carrying ``doubt`` s on top of the run's figure, as the served line stamps
    them; the others the run's figure."""
    chosen = {id(c) for c in wire.view().transmissions[index].chars}
    return [
        replace(e, uncertainty=U + (doubt if id(e) in chosen else 0.0))
        if e.kind is EventKind.CHAR and e.origin == TOOL
        else e
        for e in wire.events
    ]


def test_r_7_0_13_a_gap_between_characters_read_together_is_undecided():
    wire = Wire().brk().rec("0M!")  # laid back to back: 0 ms gaps, PASS on the stamps alone
    assert by_id(judge_character_gaps(wire.view(), 0.0))["R-7.0-13"].verdict is Verdict.PASS
    found = by_id(judge_character_gaps(read_view(doubted(wire, 0, 0.020)), 0.0))
    assert found["R-7.0-13"].verdict is Verdict.INCONCLUSIVE, found["R-7.0-13"]


def test_r_7_0_06_a_command_that_may_have_started_earlier_does_not_pass_its_marking():
    """22 ms after the break's end by the stamps; its first character may have been sent
    anywhere in the 22 ms before (a 2 ms marking, then a 20 ms pause in the command)."""
    wire = Wire().brk(marking_ms=22.0).rec("0I!")
    assert by_id(judge_breaks(wire.view(), U))["R-7.0-06"].verdict is Verdict.PASS
    found = by_id(judge_breaks(read_view(doubted(wire, 0, 0.022)), U))["R-7.0-06"]
    assert found.verdict is Verdict.INCONCLUSIVE, found


def test_r_7_0_17_a_command_that_may_have_started_earlier_does_not_fail_its_87_ms():
    wire = Wire().brk().rec("0I!").idle(105).rec("0I!")
    assert by_id(judge_break_rules(wire.view(), U))["R-7.0-17"].verdict is Verdict.FAIL
    found = by_id(judge_break_rules(read_view(doubted(wire, 1, 0.030)), U))["R-7.0-17"]
    assert found.verdict is Verdict.INCONCLUSIVE, found


def test_r_7_2_02_a_retry_that_may_have_started_earlier_is_not_timed_from_its_stamp():
    """A retry 10 ms after the unanswered command by the stamps (too soon: FAIL), its
    characters read together: where it started is known only to 30 ms, so the 16.67 ms
    floor is undecided."""
    wire = Wire().brk().rec("0M!").idle(10).rec("0M!")
    retry = by_id(judge_retries(wire.view(), U))["R-7.2-02"]
    assert retry.verdict is Verdict.FAIL, retry
    found = by_id(judge_retries(read_view(doubted(wire, 1, 0.030)), U))["R-7.2-02"]
    assert found.verdict is Verdict.INCONCLUSIVE, found


def test_characters_stamped_as_the_run_says_are_judged_as_before():
    wire = Wire().brk().rec("0M!", gap_ms=10.0)
    found = by_id(judge_character_gaps(read_view(doubted(wire, 0, 0.0)), U))["R-7.0-13"]
    assert found.verdict is Verdict.FAIL and found.uncertainty_ms == 5.0, found
