"""The judges on hand-made records: timing with uncertainty, service-request rules on the
spec's own examples, transcript segmentation, and the aggregation into verdicts."""

from __future__ import annotations

import pytest

from conformance.judges import measurements, wire
from conformance.judges.timing import StampUncertainty, judge_window
from conformance.protocol.commands import parse_command
from conformance.protocol.timing import CHAR_TIME
from conformance.results import (
    COMPLIANT,
    INCOMPLETE,
    NON_COMPLIANT,
    CaseRecord,
    aggregate,
    overall,
)
from conformance.tool_recorder.records import Attempt, Exchange, Measurement
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Finding, Verdict, worst


def chars(text: str, start: float, origin: str, gap: float = 0.0) -> list[Event]:
    out, t = [], start
    for c in text:
        out.append(Event(EventKind.CHAR, origin, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
        t += CHAR_TIME + gap
    return out


def exchange(command: str, reply: str, t: float, delay: float = 9e-3) -> Exchange:
    cmd = chars(command, t, TOOL)
    rep = chars(reply, cmd[-1].end + delay, DUT) if reply else []
    end = rep[-1].end if rep else cmd[-1].end + 0.03
    return Exchange(parse_command(command), command, [Attempt(None, cmd, rep, "ok", end)])


def measurement(reply: str, sr_at: float | None, data: list[tuple[str, str]]) -> Measurement:
    """A recorded M measurement: reply, optional service request ``sr_at`` s after it, D's."""
    start = exchange("0M!", reply, 0.0)
    m = Measurement(start.command, start, ttt=int(reply[1:4]), count=int(reply[4:]))
    m.reply_end = start.reply_events[-1].end
    t = m.reply_end + 1.0
    if sr_at is not None:
        m.waited_events = chars("0\r\n", m.reply_end + sr_at, DUT)
        m.service_request_end = m.waited_events[-1].end
        t = m.service_request_end + 0.02
    for command, reply_text in data:
        ex = exchange(command, reply_text, t)
        m.data.append(ex)
        t = ex.end + 0.02
    return m


SR_IDS = ("R-4.4.6-01", "R-4.4.6-02", "R-4.4.6-04", "R-4.4.5-08")


def verdicts(findings: list[Finding]) -> dict[str, Verdict]:
    return {f.requirement: f.verdict for f in findings}


def test_spec_example_4_4_8_4_d_no_service_request_is_flagged():
    m = measurement("00012\r\n", None, [("0D0!", "0+3.14+2.718\r\n")])
    assert verdicts(measurements.judge([m], SR_IDS, "14"))["R-4.4.6-02"] is Verdict.FAIL


def test_spec_example_4_4_8_4_b_service_request_passes():
    m = measurement("00053\r\n", 4.2, [("0D0!", "0+3.14+2.718+1.414\r\n")])
    found = verdicts(measurements.judge([m], SR_IDS, "14"))
    assert set(found.values()) == {Verdict.PASS}


def test_late_service_request_fails_its_deadline_only():
    m = measurement("00053\r\n", 5.2, [("0D0!", "0+3.14+2.718+1.414\r\n")])
    found = verdicts(measurements.judge([m], SR_IDS, "14"))
    assert found["R-4.4.6-04"] is Verdict.FAIL
    assert found["R-4.4.6-02"] is Verdict.PASS


def test_chatter_before_the_service_request_is_not_taken_for_it():
    m = measurement("00053\r\n", 4.0, [("0D0!", "0+3.14+2.718+1.414\r\n")])
    m.waited_events = chars("0x\r\n", m.reply_end + 1.0, DUT) + m.waited_events
    found = verdicts(measurements.judge([m], SR_IDS, "14"))
    assert found["R-4.4.5-08"] is Verdict.FAIL
    assert found["R-4.4.6-01"] is Verdict.PASS


@pytest.mark.parametrize(
    ("measured", "uncertainty", "expected"),
    [
        (10e-3, 0.0, Verdict.PASS),
        (15.4e-3, 0.0, Verdict.PASS),  # the limit plus its tolerance is still inside
        (15.5e-3, 0.0, Verdict.FAIL),
        (14e-3, 2e-3, Verdict.INCONCLUSIVE),  # 12..16 ms straddles 15.4 ms
        (20e-3, 2e-3, Verdict.FAIL),
        (10e-3, 2e-3, Verdict.PASS),
    ],
)
def test_timing_window_with_uncertainty(measured, uncertainty, expected):
    found = judge_window(
        "R-7.0-10", "start", measured, uncertainty, high=15e-3, evidence=["reply to 0!"]
    )
    assert found.verdict is expected
    assert found.uncertainty_ms == pytest.approx(uncertainty * 1e3)


def test_should_rule_turns_a_violation_into_warn():
    found = judge_window("R-4.4.5-09", "x", 5.0, 0.0, high=1.0, should=True, evidence=["0M!"])
    assert found.verdict is Verdict.WARN


def transcript_of(*exchanges: Exchange) -> list[Event]:
    events = [e for ex in exchanges for a in ex.attempts for e in a.command_events + a.reply_events]
    return sorted(events, key=lambda e: e.start)


def test_segments_and_response_window():
    ok = exchange("0!", "0\r\n", 0.0, delay=9e-3)
    late = exchange("0I!", "013ABCDEFGHIJKLMN100\r\n", 1.0, delay=20e-3)
    segs = wire.segments(transcript_of(ok, late))
    assert [s.text for s in segs] == ["0!", "0I!"]
    found = verdicts(wire.judge_response_start(segs, 0.0))
    assert found == {"R-7.0-09": Verdict.PASS, "R-7.0-10": Verdict.FAIL}


def test_characters_talking_over_a_command_are_contention_not_a_reply():
    cmd = chars("0D0!", 0.0, TOOL)
    clash = chars("0\r\n", CHAR_TIME * 1.5, DUT)  # starts inside the command
    segs = wire.segments(sorted(cmd + clash, key=lambda e: e.start))
    assert segs[0].reply == [] and segs[0].contention


def test_gaps_judged_without_tolerance_and_tolerance_misuse_flagged():
    tight = exchange("0!", "", 0.0)
    tight.attempts[0].reply_events = chars(
        "0123\r\n", tight.last.command_end + 9e-3, DUT, gap=1.9e-3
    )
    found = verdicts(wire.judge_gaps(wire.segments(transcript_of(tight)), 0.0))
    assert found == {"R-7.0-12": Verdict.FAIL, "R-7.0-01": Verdict.FAIL}
    far = exchange("0!", "", 0.0)
    far.attempts[0].reply_events = chars("0123\r\n", far.last.command_end + 9e-3, DUT, gap=3e-3)
    found = verdicts(wire.judge_gaps(wire.segments(transcript_of(far)), 0.0))
    assert found == {"R-7.0-12": Verdict.FAIL, "R-7.0-01": Verdict.PASS}


def test_bit_rate_too_fast_fails_but_slow_is_never_guessed():
    fast = exchange("0!", "", 0.0)
    t0 = fast.last.command_end + 9e-3
    fast.attempts[0].reply_events = [
        Event(EventKind.CHAR, DUT, t0 + i * 7.7e-3, t0 + (i + 1) * 7.7e-3, wire=0x30)
        for i in range(4)
    ]
    fast_segs = wire.segments(transcript_of(fast))
    assert wire.judge_reply_bit_rate(fast_segs, 0.0).verdict is Verdict.FAIL
    gapped = exchange("0!", "", 0.0)
    gapped.attempts[0].reply_events = chars("0123", gapped.last.command_end + 9e-3, DUT, gap=1e-3)
    assert (
        wire.judge_reply_bit_rate(wire.segments(transcript_of(gapped)), 0.0).verdict
        is Verdict.INCONCLUSIVE
    )


@pytest.mark.parametrize("spacing", [0.0, 1e-8, 2e-3])
def test_bit_rate_from_stamps_no_character_can_have_is_undecided(spacing):
    """Issue 19: behind the echo bench one read stamped two characters together and the
    detail said "about 1000000628 baud" / "about inf baud": such a spacing is the stamps',
    not a rate (and no FAIL either)."""
    burst = exchange("0!", "", 0.0)
    t0 = burst.last.command_end + 9e-3
    burst.attempts[0].reply_events = [
        Event(EventKind.CHAR, DUT, t0 + i * spacing, t0 + i * spacing + CHAR_TIME, wire=0x30)
        for i in range(4)
    ]
    segs = wire.segments(transcript_of(burst))
    for stamps in (5e-3, StampUncertainty(0.5e-3, lambda a, b: 5e-3)):
        found = wire.judge_reply_bit_rate(segs, stamps)
        assert found.verdict is Verdict.INCONCLUSIVE, found
        assert "baud" not in found.detail.replace("1200-baud", "")  # no figure of a rate


def test_aggregation_worst_finding_untestable_and_unjudged():
    case = CaseRecord(
        "t::a",
        "a",
        ("R-4.4.1-01",),
        findings=[
            Finding("R-4.4.1-01", Verdict.PASS, "ok", observed=1),
            Finding("R-4.4.1-01", Verdict.WARN, "hm", observed=1, evidence=["0! -> '0 '"]),
        ],
    )
    results = {r.requirement.id: r for r in aggregate("sensor", [case])}
    assert results["R-4.4.1-01"].verdict is Verdict.WARN
    assert results["R-3.1-01"].verdict is Verdict.NA  # electrical: untestable here
    assert results["R-4.4.2-01"].verdict is Verdict.INCONCLUSIVE  # no case ran for it
    assert worst([Verdict.PASS, Verdict.FAIL, Verdict.WARN]) is Verdict.FAIL


@pytest.mark.parametrize(
    ("exploration", "case", "expected"),
    [
        # seed 4197: the one repeated D0 beside the retention case that met no precondition
        (Verdict.PASS, "unreached", Verdict.INCONCLUSIVE),
        (Verdict.PASS, Verdict.PASS, Verdict.PASS),  # beside the whole rule's PASS it stands
        (Verdict.FAIL, "unreached", Verdict.FAIL),  # a clause broken breaks the rule
    ],
)
def test_a_partial_pass_does_not_outvote_the_case_built_for_the_whole_rule(
    exploration, case, expected
):
    rid = "R-4.4.5-10"
    evidence = {"evidence": ["0D0! -> '0+1'"]} if exploration is Verdict.FAIL else {}
    partial = Finding(rid, exploration, "held", observed=1, partial=True, **evidence)
    if case == "unreached":
        whole = Finding(rid, Verdict.INCONCLUSIVE, "precondition not met: buffered")
    else:
        whole = Finding(rid, case, "4 D replies identical", observed=4)
    records = [CaseRecord("t::e", "e", (rid,), findings=[partial])]
    records.append(CaseRecord("t::r", "r", (rid,), findings=[whole]))
    results = {r.requirement.id: r for r in aggregate("sensor", records)}
    assert results[rid].verdict is expected


@pytest.mark.parametrize("beside", [None, Verdict.NA])
def test_r_4_4_5_10_a_partial_pass_alone_does_not_pass_the_rule(beside):
    """A run of the exploration alone (-k, --req) checks one clause of R-4.4.5-10:
    INCONCLUSIVE, naming the clause it checked, never a PASS of the rule."""
    rid = "R-4.4.5-10"
    findings = [Finding(rid, Verdict.PASS, "held over 3 checks", observed=3, partial=True)]
    if beside is not None:
        findings.append(Finding(rid, beside, "not supported"))
    records = [CaseRecord("t::e", "e", (rid,), findings=findings)]
    results = {r.requirement.id: r for r in aggregate("sensor", records)}
    assert results[rid].verdict is Verdict.INCONCLUSIVE
    assert "held over 3 checks" in results[rid].one_line
    assert "no case judged the rest" in results[rid].one_line


def test_a_whole_rules_pass_still_outvotes_an_unreached_case():
    rid = "R-4.4.5-10"
    findings = [
        Finding(rid, Verdict.PASS, "held", observed=1),
        Finding(rid, Verdict.INCONCLUSIVE, "the exploration stopped early"),
    ]
    results = {
        r.requirement.id: r
        for r in aggregate("sensor", [CaseRecord("t", "t", (rid,), findings=findings)])
    }
    assert results[rid].verdict is Verdict.PASS


def test_partial_is_the_runs_weighing_not_a_field_of_verdicts_json():
    finding = Finding("R-4.4.5-10", Verdict.PASS, "held", observed=1, partial=True)
    assert "partial" not in finding.to_json()


def test_overall_verdict():
    case = CaseRecord(
        "t::a",
        "a",
        ("R-4.4.1-01",),
        findings=[Finding("R-4.4.1-01", Verdict.WARN, "hm", observed=1, evidence=["0!"])],
    )
    results = aggregate("sensor", [case])
    assert overall(results, strict=False, complete=True) == INCOMPLETE  # others unjudged
    results = [r for r in results if r.judged]
    assert overall(results, strict=False, complete=True) == COMPLIANT
    assert overall(results, strict=True, complete=True) == NON_COMPLIANT
    assert overall(results, strict=False, complete=False) == INCOMPLETE


def test_cases_needing_what_the_link_lacks_are_inconclusive():
    from types import SimpleNamespace

    from conformance.links.base import LinkInfo
    from conformance.plugin import missing_capabilities

    item = SimpleNamespace(
        get_closest_marker=lambda name: (
            SimpleNamespace(args=("break", "unsolicited")) if name == "needs" else None
        )
    )
    socket_like = SimpleNamespace(link=SimpleNamespace(info=LinkInfo("socket", can_break=False)))
    assert missing_capabilities(item, socket_like) == ["send breaks"]
    sim = SimpleNamespace(link=SimpleNamespace(info=LinkInfo("sim")))
    assert missing_capabilities(item, sim) == []


def test_tolerance_misuse_needs_the_gap_surely_in_the_band():
    gapped = exchange("0!", "", 0.0)
    gapped.attempts[0].reply_events = chars(
        "0123\r\n", gapped.last.command_end + 9e-3, DUT, gap=1.9e-3
    )
    segs = wire.segments(transcript_of(gapped))
    assert verdicts(wire.judge_gaps(segs, 0.1e-3))["R-7.0-01"] is Verdict.FAIL
    assert verdicts(wire.judge_gaps(segs, 0.5e-3))["R-7.0-01"] is Verdict.INCONCLUSIVE


@pytest.mark.parametrize(
    ("frame", "verdict"),
    [(8.330e-3, Verdict.PASS), (8.000e-3, Verdict.FAIL), (8.670e-3, Verdict.FAIL)],
)
def test_bit_rate_from_frame_lengths_sees_slow_as_well_as_fast(frame, verdict):
    """Where each event lasts its own measured frame (a firmware kit), its length is its
    rate: a sender 4 % slow, with gaps between its characters, FAILs too (the spacing judge
    cannot tell that from a gap), and one exact frame among slow ones does not hide them."""
    ex = exchange("0!", "", 0.0)
    t0 = ex.last.command_end + 9e-3
    ex.attempts[0].reply_events = [
        Event(EventKind.CHAR, DUT, t0, t0 + 8.33e-3, wire=0x30),
        *(
            Event(EventKind.CHAR, DUT, t0 + i * 9e-3, t0 + i * 9e-3 + frame, wire=0x30)
            for i in range(1, 4)
        ),
    ]
    found = wire.judge_reply_frame_lengths(wire.segments(transcript_of(ex)), 0.0)
    assert found.verdict is verdict, found
    assert found.observed == 1 and "4 frames" in found.detail
    assert wire.judge_reply_frame_lengths([], 0.0).verdict is Verdict.INCONCLUSIVE
