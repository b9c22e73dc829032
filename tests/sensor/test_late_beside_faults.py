"""Rows of the replies-after-retry pairs (truth18), each run on the one case that judges it.

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then)
beside another fault: a reply that came late, or may be the command before's, is neither
silence nor this command's answer. Each test fails on 832cfdc (the verdict before named).
"""

from __future__ import annotations

from conformance.conduct import run_once


def _row(faults: str, keyword: str, rid: str) -> dict:
    data = run_once(f"sim://?faults={faults}", keyword=keyword)
    return next(r for r in data["requirements"] if r["id"] == rid)


def test_r_7_0_04_late_answers_to_the_tries_after_the_break_are_answers() -> None:
    """never-standby + replies-after-retry: each a! after the 12.6 ms break was answered
    80 ms later, between the tries: "no reply to a! or 2 retries" FAILed. The last try is
    listened to as a late sensor's one-shot probes are (SensorSession.hear_late)."""
    faults = "never-standby,replies-after-retry"
    found = _row(faults, "test_break_just_over_12ms_wakes", "R-7.0-04")
    assert found["verdict"] == "PASS", found["findings"]  # FAIL before
    assert "0! -> late '0<CR><LF>'" in found["findings"][0]["detail"]


def test_r_7_0_15_a_probe_answered_with_the_retry_s_late_reply_is_set_aside() -> None:
    """parity-error + replies-after-retry: the wake-up a!'s invalid reply drew a retry whose
    reply came 3 ms after the standby probe: "answered although 101.90 ms ... put it in
    standby" FAILed; that probe is set aside, the one silent after 115 ms PASSes."""
    found = _row("parity-error,replies-after-retry", "test_standby_after_100ms", "R-7.0-15")
    assert found["verdict"] == "PASS", found["findings"]  # FAIL before
    assert "may be 0!'s late reply" in found["findings"][0]["detail"]
