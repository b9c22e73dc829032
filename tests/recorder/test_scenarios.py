"""Issue 20, "scenarios that real code gets wrong": a ttt over 255 s, a concurrent ttt = 000,
a parity error in the middle of a D0 reply, a reply starting at the edge of the 15.40 ms
window. Each scenario's sensor does what its title says, the golden recorder copes with it,
and the judges it feeds fail the deviation a real logger library was seen to make (the
recorder matrix rows of ttt-8-bit, concurrent-ttt-zero-stalls, drops-after-parity-error and
short-reply-timeout prove the whole suite catches exactly those)."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.collection import judge_data_collection
from conformance.judges.recorder.logged import LogReport, judge_logged_values
from conformance.judges.recorder.measurements import observed_measurements
from conformance.judges.recorder.replies import reply_problem
from conformance.judges.recorder.retries import judge_retries
from conformance.judges.recorder.waits import judge_measure_waits
from conformance.recorder.faults import RECORDER_FAULTS
from conformance.recorder.scenario_runner import RecorderSession
from conformance.recorder.scenarios import EDGE_REPLY, LONG_TTT, LONG_TTT_READY, SCENARIOS
from conformance.verdicts import Verdict
from conformance.view.segments import read_view
from tests.judges.recorder.test_recorder_judges import Wire, by_id

NEW = ("ttt-over-255", "concurrent-ttt-zero", "parity-mid-reply", "reply-at-window-edge")


def _line(port: str, name: str):
    session = RecorderSession(port)
    run = session.run(name)
    return read_view(run.events, session.is_recorder), run


@pytest.fixture(scope="module")
def golden():
    return {name: _line("sim", name) for name in NEW}


def test_the_scenarios_exist_with_a_title():
    for name in NEW:
        assert SCENARIOS[name].title and name in SCENARIOS


def test_ttt_over_255_sensor_and_the_golden_recorder(golden):
    line, run = golden["ttt-over-255"]
    start, d0 = line.transmissions[0], line.transmissions[1]
    assert start.text == "0M!" and bytes(e.wire & 0x7F for e in start.reply) == b"02603\r\n"
    assert LONG_TTT > 255 and LONG_TTT % 256 < LONG_TTT_READY < LONG_TTT
    # the golden recorder waits for the service request, 6 s after the reply
    waited = d0.start - start.reply[-1].end
    assert LONG_TTT_READY <= waited < LONG_TTT_READY + 0.1
    assert run.output.logged["0M!"] == ["+22.15", "+1013.2", "+45.7"]


def test_eight_bit_ttt_is_judged_early():
    """aD0! 4 s after ttt = 260 (260 % 256), before the service request: R-4.4.5-04 fails."""
    w = Wire().brk().rec("0M!").sensor("02603\r\n").idle(4005).brk().rec("0D0!")
    w.sensor("0\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))
    assert found["R-4.4.5-04"].verdict is Verdict.FAIL
    assert found["R-4.4.5-07"].verdict is Verdict.FAIL
    w = Wire().brk().rec("0M!").sensor("02603\r\n").sensor("0\r\n", delay_ms=5000)
    w.idle(9).rec("0D0!").sensor("0+1+2+3\r\n")
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))
    assert found["R-4.4.5-04"].verdict is Verdict.PASS


def test_eight_bit_ttt_with_a_second_of_slack_is_judged_early():
    """EnviroDIY's d_simple_logger (outside32) reads ttt into a ``uint8_t`` and waits
    ``(wait + 1) * 1000`` ms from 0.1 s after its command: 5.1 s for ttt = 260. With the
    scenario's service request at 5 s it heard the request first and R-4.4.5-04 PASSed;
    the request now comes later than such a wait, so its aD0! comes first and FAILs."""
    waited_ms = round(((LONG_TTT % 256) + 1 + 0.1) * 1000)
    w = Wire().brk().rec("0M!").sensor("02603\r\n").idle(waited_ms).brk().rec("0D0!")
    w.sensor("0\r\n")
    assert waited_ms < LONG_TTT_READY * 1000  # the request would still have been due
    found = by_id(judge_measure_waits(observed_measurements(w.view(), 0.0), 0.0))
    assert found["R-4.4.5-04"].verdict is Verdict.FAIL


def test_concurrent_ttt_zero_sensor_and_the_golden_recorder(golden):
    line, run = golden["concurrent-ttt-zero"]
    texts = [t.text for t in line.transmissions]
    assert texts == ["0C!", "1C!", "0D0!", "1D0!"]
    assert bytes(e.wire & 0x7F for e in line.transmissions[0].reply) == b"000005\r\n"
    assert len(run.output.logged["0C!"]) == len(run.output.logged["1C!"]) == 5


def test_a_concurrent_ttt_zero_never_collected_fails_the_collection_rule():
    w = Wire().brk().rec("0C!").sensor("000005\r\n").idle(20).brk().rec("1C!")
    w.sensor("100205\r\n", origin="sensor1").idle(2100).brk().rec("1D0!")
    w.sensor("1+1+2+3+4+5\r\n", origin="sensor1")
    found = judge_data_collection(observed_measurements(w.view(), 0.0))
    assert found[0].verdict is Verdict.FAIL and "0C!" in found[0].detail


def test_parity_mid_reply_sensor_and_the_golden_recorder(golden):
    line, run = golden["parity-mid-reply"]
    d0 = [t for t in line.transmissions if t.text == "0D0!"]
    assert len(d0) == 2  # the spoiled reply, then the golden recorder's retry
    bad = [i for i, e in enumerate(d0[0].reply) if not e.parity_ok]
    assert bad == [10] and len(d0[0].reply) == len(d0[1].reply)
    assert by_id(judge_retries(line, 0.0))["R-7.2-05"].verdict is Verdict.PASS
    assert run.output.logged["0M!"] == ["+22.15", "+1013.2", "+45.7"]


def test_a_parity_error_mid_reply_not_retried_fails_r_7_2_05():
    w = Wire().brk().rec("0D0!").sensor("0+22.15+10", delay_ms=9.0)
    w.chars("1", "sensor0", parity=False).chars("3.2+45.7\r\n", "sensor0")
    w.idle(10).rec("0D1!").sensor("0\r\n")
    found = by_id(judge_retries(w.view(), 0.0))
    assert found["R-7.2-05"].verdict is Verdict.FAIL and "parity" in found["R-7.2-05"].detail


def test_reply_at_window_edge_sensor_and_the_golden_recorder(golden):
    line, run = golden["reply-at-window-edge"]
    for t in line.transmissions:
        assert t.reply[0].start - t.end == pytest.approx(EDGE_REPLY)
        assert reply_problem(t, None, 0.0) is None  # inside R-7.0-10's 15.40 ms: valid
    assert [t.text for t in line.transmissions] == ["0M!", "0D0!"]
    assert run.output.logged["0M!"] == ["+22.15", "+1013.2", "+45.7"]


def test_short_reply_timeout_loses_the_window_edge_reply():
    line, run = _line("sim://?recorder-faults=short-reply-timeout", "reply-at-window-edge")
    assert not any(t.text == "0D0!" for t in line.transmissions)  # never got to the data
    assert run.output.logged["0M!"] == []
    found = by_id(judge_retries(line, 0.0))
    assert found["R-7.2-05"].verdict is Verdict.FAIL
    collected = judge_data_collection(observed_measurements(line, 0.0))
    assert collected[0].verdict is Verdict.FAIL
    assert "R-4.4.8-05" in RECORDER_FAULTS["short-reply-timeout"].violates


def test_values_logged_from_a_reply_with_a_parity_error_fail_r_4_4_02():
    """A D0 reply with a parity error and no valid one after it: logging nothing from it is
    fine, logging the values before the bad character is a FAIL."""
    w = Wire().brk().rec("0M!").sensor("00003\r\n").idle(9).rec("0D0!")
    w.sensor("0+22.15+10").chars("1", "sensor0", parity=False).chars("3.2+45.7\r\n", "sensor0")
    line = w.view()
    kept = judge_logged_values(line, [LogReport("p", {"0M!": ["+22.15", "+10"]})], 0.0)
    found = by_id(kept)["R-4.4-02"]
    assert found.verdict is Verdict.FAIL and "not valid" in found.detail
    clean = judge_logged_values(line, [LogReport("p", {"0M!": []})], 0.0)
    assert by_id(clean)["R-4.4-02"].verdict is not Verdict.FAIL
