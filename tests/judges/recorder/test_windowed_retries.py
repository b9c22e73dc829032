"""The recorder's retries judged a window at a time (issue 22's windowed judge):
:class:`~conformance.judges.recorder.retries.Retries` given each window's view, read from
its own events alone, in order gives :func:`judge_retries`' findings of the whole recording
(``testcases/passive/test_recorder_4_4_measurement.py::test_retries``, R-7.2-01..06),
detail for detail and evidence for evidence.

What a wrong merge gets wrong: a command's tries spread over windows (its break+command+
retries sequences, each after a break: R-7.2-04 counts them, R-7.2-03 judges each), the
tally's count over every window (R-7.2-05's PASS), and a reply the recorder's break cut
into (R-7.2-06's FAIL) in a window before the last."""

from __future__ import annotations

from conformance.judges.recorder.retries import Retries, judge_retries
from conformance.transcript import Event
from conformance.verdicts import Finding, Verdict
from conformance.view.segments import read_view
from tests.support.bus_of_sensors import as_heard, bus_of_sensors, start
from tests.support.hand_events import sent, woken
from tests.support.windowed_judges import at_every_break, product_cuts

U = 1e-6  # a 1 MHz capture's stamps


def _windowed(windows: list[list[Event]]) -> list[Finding]:
    judge = Retries(U)
    for window in windows:
        judge.add(read_view(window))
    return judge.findings()


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def _unanswered_polls() -> list[Event]:
    """Sensor 0 identified, then ``5!``, ``6!`` and ``7!`` (nobody there), each retried
    twice in each of three break+command+retries sequences, sensor 0 identified between."""
    bus, recorder = bus_of_sensors("0")
    recorder.identify("0")
    for a in "567":
        recorder.transact(f"{a}!")
        recorder.identify("0")
    return as_heard(bus)


def test_a_commands_sequences_in_windows_of_their_own_judge_as_the_whole():
    events = _unanswered_polls()
    whole = judge_retries(read_view(events), U)
    found = _by_rule(whole)
    assert found["R-7.2-04"].verdict is Verdict.PASS
    assert found["R-7.2-03"].verdict is Verdict.PASS and found["R-7.2-03"].observed == 9
    assert found["R-7.2-05"].verdict is Verdict.PASS and found["R-7.2-05"].observed == 3
    windows = at_every_break(events)
    assert len(windows) == 13  # 0I! four times, 5!, 6!, 7! three sequences each
    assert _windowed(windows) == whole
    for windows in product_cuts(events, U):
        assert len(windows) == 7
        assert _windowed(windows) == whole


def test_a_reply_cut_in_an_early_window_fails_as_in_the_whole():
    """The recorder breaks into ``0I!``'s reply after seven characters and sends ``0I!``
    again (R-7.2-06 FAIL: it did not wait for the response to complete), then asks 1I! and
    3I!, each a window of its own: the FAIL stands from the first window."""
    events: list[Event] = []
    t = sent(events, woken(events, 0.05, "0I!"), "014CONF") + 0.001
    t = sent(events, woken(events, t, "0I!"), "014CONFORM EMU001100\r\n") + 0.2
    t = sent(events, woken(events, t, "1I!"), "114CONFORM EMU001100\r\n") + 0.2
    sent(events, woken(events, t, "3I!"), "314CONFORM EMU001100\r\n")
    whole = judge_retries(read_view(events), U)
    r6 = _by_rule(whole)["R-7.2-06"]
    assert r6.verdict is Verdict.FAIL and "did not wait for the response" in r6.detail
    for windows in product_cuts(events, U):
        assert len(windows) == 3
        assert _windowed(windows) == whole


def test_invalid_replies_retried_over_windows_judge_as_the_whole():
    """A sensor whose D replies after ``0MC!`` lack their CRC: each ``0D0!`` retried in
    three sequences (R-7.2-06 times each retry from the end of the invalid reply, read in
    that sequence's own window), then ``1I!``, then ``0D0!`` read again in a window of its
    own, still judged by 0MC!'s CRC expectation (carried), so retried as due again."""
    bus, recorder = bus_of_sensors("01", faults={"0": ["crc-missing"]})
    m = start(recorder, "0MC!")
    recorder.link.wait_until(recorder.link.now() + m.ttt + 0.1)
    recorder.collect(m, force_break=True, max_index=0)
    recorder.identify("1")
    recorder.transact("0D0!", force_break=True)
    events = as_heard(bus)
    whole = judge_retries(read_view(events), U)
    found = _by_rule(whole)
    assert found["R-7.2-06"].verdict is Verdict.PASS and found["R-7.2-06"].observed == 12
    assert found["R-7.2-05"].observed == 2  # both 0D0! groups, the one read again too
    windows = at_every_break(events)
    assert len(windows) == 8
    assert _windowed(windows) == whole
    for windows in product_cuts(events, U):
        assert len(windows) == 3
        assert _windowed(windows) == whole
