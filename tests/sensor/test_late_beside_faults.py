"""Rows of the replies-after-retry pairs (truth18), each run on the one case that judges it.

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then)
beside another fault: a reply that came late, or may be the command before's, is neither
silence nor this command's answer. Each test fails on 832cfdc (the verdict before named).
The fault alone, judged on its whole run, is tests/judges/test_late_reply_whole_run.py's
(its high-volume rules too: that run made once, not once more here).
"""

from __future__ import annotations

from conformance.conduct import run_once

KEYWORD_7_0_04 = "test_break_just_over_12ms_wakes"


def _row(faults: str, keyword: str, rid: str) -> dict:
    data = run_once(f"sim://?faults={faults}", keyword=keyword)
    return next(r for r in data["requirements"] if r["id"] == rid)


def test_r_7_0_04_late_answers_to_the_tries_after_the_break_are_answers() -> None:
    """late-address-after-break + replies-after-retry: each a! after the 12.6 ms break was
    answered 80 ms later, between the tries: "no reply to a! or 2 retries" FAILed. The last
    try is listened to as a late sensor's one-shot probes are (SensorSession.hear_late)."""
    found = _row("late-address-after-break,replies-after-retry", KEYWORD_7_0_04, "R-7.0-04")
    assert found["verdict"] == "PASS", found["findings"]  # FAIL before
    assert "0! -> late '0<CR><LF>'" in found["findings"][0]["detail"]


def test_r_7_0_04_a_sensor_answering_the_check_late_is_not_shown_asleep() -> None:
    """never-standby + replies-after-retry: the a! without a break that shows the sensor in
    standby was answered 80 ms later, past its window, and the sensor that never sleeps was
    taken as asleep (R-7.0-04 FAILed "no reply to a! or 2 retries"): the check is listened
    to as a late sensor's one-shots are, and the standby precondition is not met."""
    found = _row("never-standby,replies-after-retry", KEYWORD_7_0_04, "R-7.0-04")
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # FAIL before
    assert "not shown in standby" in found["findings"][0]["detail"]
    assert "0! -> late '0<CR><LF>'" in found["findings"][0]["detail"]


def test_r_7_0_15_a_probe_answered_with_the_retry_s_late_reply_is_set_aside() -> None:
    """parity-error + replies-after-retry: the wake-up a!'s invalid reply drew a retry whose
    reply came 3 ms after the standby probe: "answered although 101.90 ms ... put it in
    standby" FAILed; that probe is set aside. The one silent "after 115 ms" came only 60 ms
    after that retry's late reply (outside28 counts the marking from the last character on
    the line, late replies included): no probe landed after 100 ms of marking, INCONCLUSIVE
    (it PASSed on the 115 ms, which ignored the late reply)."""
    found = _row("parity-error,replies-after-retry", "test_standby_after_100ms", "R-7.0-15")
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # FAIL, then PASS before
    assert "is not surely over" in found["findings"][0]["detail"]


def test_r_4_4_6_03_and_4_4_5_03_after_a_start_that_drew_no_reply_are_undecided() -> None:
    """replies-after-retry + slow-wake (the whole run: its timing brings it about): 0M1!'s
    tries met the sensor only after each break's 110 ms wake-up and its '00002' came 80 ms
    after the last, in the 0.5 s listened to for a service request: R-4.4.6-03 FAILed "sent
    '00002<CR><LF>' after '' announced ttt = 000" and R-4.4.5-03 "aD0! right after ttt = 000
    gave no values: 0D0! -> '(silence)'". No start reply, no ttt = 000 announced, no
    measurement shown started: INCONCLUSIVE, each naming it."""
    data = run_once("sim://?faults=replies-after-retry,slow-wake")
    found = {r["id"]: r for r in data["requirements"]}
    # since truth20 the engine listens past an exchange whose every try went unanswered
    # until the late reply is over, so the sensor hears the next command: 0M1! is answered
    # '00002' in its window, and R-4.4.6-03 PASSes "no service request in 0.5 s" (the
    # sensor keeps the rule); neither rule FAILs on another command's reply
    for rid in ("R-4.4.6-03", "R-4.4.5-03"):
        assert found[rid]["verdict"] in ("PASS", "INCONCLUSIVE"), found[rid]["findings"]
        assert "0M1!" in found[rid]["findings"][0]["detail"] or found[rid]["verdict"] != "PASS"


def test_r_4_4_8_03_counts_of_late_starts_unread_are_not_a_pass() -> None:
    """high-volume-two-digit-count + replies-after-retry (seed 4900): the announced-count
    rules PASSed on the eight starts read, "conforms (8 checked ...)", while 0MC1!, 0MC2!...
    and 0HA! (the fault's own: a count unreadable) were answered only late and their counts
    never read: a missed FAIL. INCONCLUSIVE, naming the unread starts."""
    data = run_once(
        "sim://?faults=high-volume-two-digit-count,replies-after-retry",
        keyword="test_announced_values_delivered",
    )
    found = {r["id"]: r for r in data["requirements"]}
    for rid in ("R-4.4.8-03", "R-4.4.8-04"):
        assert found[rid]["verdict"] == "INCONCLUSIVE", found[rid]["findings"]  # PASS before
        assert any(
            "not every start's count was read" in f["detail"] for f in found[rid]["findings"]
        )


def test_r_4_4_8_1_03_unsupported_crc_forms_answered_late_are_not_a_pass() -> None:
    """unsupported-rc-without-crc + replies-after-retry (truth19; continuous-over-75 beside
    them, seed 5000-5030's triples, the same): aRC2!..aRC9!, the fault's own replies, came
    only after the reply window, and the empty-reply rule PASSed "conforms (8 checked: 0R2!,
    ..., 0R9!)" on the plain ones: a missed FAIL. INCONCLUSIVE, naming the late replies."""
    found = _row(
        "replies-after-retry,unsupported-rc-without-crc", "test_continuous_replies", "R-4.4.8.1-03"
    )
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # PASS before
    assert "0RC2! -> late '0<CR><LF>'" in found["findings"][0]["detail"]


def test_replies_after_the_last_try_beside_slow_wake_are_late_not_silence() -> None:
    """replies-after-retry + slow-wake (the whole run: its timing brings it about): each
    sequence's third try alone was heard, after the break's 110 ms wake-up, and the reply to
    the last came 80 ms after it, in no record (truth20). R-4.4-01 FAILed "no reply although
    it is a basic command: ?!", R-4.4.5.1-03 "after the abort M got no reply", R-4.4.8-01
    "0C9! 0D0!: no reply to 0D0!" (its reply held 88.33 ms by 0IMC_001!'s character),
    R-4.4.8-03 "0 values were returned for 99 announced"; the restore, reading no answer,
    stopped the run at the address change. Past it, R-4.4.3-01 ("?!: no reply"), R-4.3-03
    ("refused or lost address(es)") and R-4.4.12-04 ("0M2! announced 9 but 0MC2! 2": 0MC1!'s
    late '00002') were false too, and R-7.0-15's case raised on a wake-up answered late."""
    data = run_once("sim://?faults=replies-after-retry,slow-wake")
    found = {r["id"]: r for r in data["requirements"]}
    assert not (data.get("run") or {}).get("stop_reason"), data["run"]  # stopped before
    for rid in ("R-4.4-01", "R-4.4.5.1-03", "R-4.4.8-01", "R-4.4.8-03", "R-4.4.3-01"):
        assert found[rid]["verdict"] == "INCONCLUSIVE", found[rid]["findings"]
    assert "?! -> late '0<CR><LF>'" in found["R-4.4.3-01"]["findings"][0]["detail"]
    for rid in ("R-4.3-03", "R-4.4.12-04", "R-7.0-15"):
        assert found[rid]["verdict"] not in ("FAIL", "WARN", "ERROR"), found[rid]["findings"]
