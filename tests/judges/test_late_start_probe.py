"""R-7.0-10 on a sensor whose every reply begins after the recorder's retry (truth10).

The Arduino Due sensor of docs/kit.md's eighteenth round waits 80 ms before every reply: the
tool retries 55 ms after an unanswered try and the reply begins ~8 ms after the retry. Since
8752f03 such a reply counts only where both readings (80 ms from the try, 8 ms from the
retry) agree, so R-7.0-10 was INCONCLUSIVE for a sensor plainly late. Now the case sends one
a! once after a break, listens 1 s with no retry, and times the reply from that command.
"""

from __future__ import annotations

from conformance.conduct import run_once
from conformance.emulator import sim_sensor
from conformance.judges import wire
from conformance.sensor.session import SensorSession
from conformance.verdicts import Verdict
from conformance.view.runs import transcript_segments


def _session(*faults: str) -> SensorSession:
    _, link, _ = sim_sensor(faults=faults)
    sensor = SensorSession(link, address="0")
    sensor.standard_stimuli()
    return sensor


def _late(sensor: SensorSession):
    segs = transcript_segments(sensor.link.transcript)
    return wire.judge_response_start(segs, sensor.stamp_uncertainty)[1]


def test_r_7_0_10_every_reply_after_a_retry_is_undecided_then_probed():
    sensor = _session("replies-after-retry")
    segs = transcript_segments(sensor.link.transcript)
    assert wire.starts_after_a_retry(segs, sensor.stamp_uncertainty)
    assert _late(sensor).verdict is Verdict.INCONCLUSIVE  # the run's own replies: undecided
    probe = sensor.late_start_probe()
    assert not probe.answered  # the engine listened 30 ms; the reply came in the 1 s after
    found = _late(sensor)
    assert found.verdict is Verdict.FAIL, found.detail
    assert found.measured_ms is not None and abs(found.measured_ms - 80.0) < 0.01
    assert found.observed == 1


def test_r_7_0_10_a_run_with_replies_timed_sends_no_probe():
    """The clean run times its replies: nothing more goes on the bus (its bus time kept)."""
    sensor = _session()
    segs = transcript_segments(sensor.link.transcript)
    assert not wire.starts_after_a_retry(segs, sensor.stamp_uncertainty)
    assert _late(sensor).verdict is Verdict.PASS


def test_r_7_0_10_an_in_time_reply_to_the_probe_is_evidence():
    """The probe's reply, when in time, is timed like any: a clean sensor's counts."""
    sensor = _session()
    before = _late(sensor).observed
    sensor.late_start_probe()
    after = _late(sensor)
    assert after.verdict is Verdict.PASS and after.observed == before + 1


def test_r_7_0_10_the_whole_run_case_fails_the_late_sensor():
    """INCONCLUSIVE 'no reply was observed' before (8752f03's agreement rule)."""
    data = run_once("sim://?faults=replies-after-retry", keyword="test_response_start_window")
    found = next(r for r in data["requirements"] if r["id"] == "R-7.0-10")
    assert found["verdict"] == "FAIL", found["findings"]
    assert "80.00 ms" in found["findings"][0]["detail"]
