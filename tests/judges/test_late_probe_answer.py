"""A silence probe answered with what may be the command before's late reply (truth18).

parity-error or ack-trailing-space beside replies-after-retry: the wake-up a!'s reply was
invalid, so the engine retried it; the sensor, 80 ms late and deaf until it answers, sent
the retry's '0<CR><LF>' 3 ms after R-7.0-15's probe, which it never heard, and the rule
FAILed "answered although 101.90 ms ... of marking put it in standby". The probe's answer
may be the retry's: set aside, neither an answer nor silence. Fails on 832cfdc.
"""

from __future__ import annotations

from conformance.judges import exchanges as xjudge
from conformance.verdicts import Verdict
from tests.judges.test_late_before import _after_unanswered, _exchange


def test_r_7_0_15_a_probe_answered_with_the_retry_s_late_reply_is_not_answered() -> None:
    probe = _after_unanswered("0!", "0!", "0\r\n")
    wake = _exchange("0!", 1.0, "0\r\n")
    found = xjudge.silent("R-7.0-15", [probe], "in standby", baseline=wake)
    assert found.verdict is Verdict.INCONCLUSIVE, found  # FAIL "answered although" before
    assert "may be 0!'s late reply" in found.detail


def test_r_7_0_15_a_silent_probe_beside_it_passes_and_an_own_answer_fails() -> None:
    wake = _exchange("0!", 1.0, "0\r\n")
    silent = _exchange("0!", 2.0)
    found = xjudge.silent(
        "R-7.0-15", [_after_unanswered("0!", "0!", "0\r\n"), silent], "in standby", baseline=wake
    )
    assert found.verdict is Verdict.PASS and "1 command(s) set aside" in found.detail, found
    answered = _exchange("0!", 3.0, "0\r\n")  # answered in its own window, nothing before
    found = xjudge.silent("R-7.0-15", [answered], "in standby", baseline=wake)
    assert found.verdict is Verdict.FAIL
