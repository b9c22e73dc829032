"""Rows of the service-request-after-ttt-zero pairs (truth19): the whole run, once a module
(its order brings the collisions about; the case alone explores no ttt = 000).

The service-request-after-ttt-zero sensor sends 'a<CR><LF>' after a start reply that
announced ttt = 000. Beside a fault that moves its replies (replies-after-retry: every
reply 80 ms after its command, deaf until then) that request is what the tool's next try
or next command takes: a service request's words are no reply where the sensor was not
shown answering. Each test fails on the base (s60) with the verdict named.
"""

from __future__ import annotations

import pytest

from conformance.conduct import run_once


@pytest.fixture(scope="module")
def late_pair() -> dict[str, dict]:
    """replies-after-retry beside service-request-after-ttt-zero: requirement ID -> row."""
    data = run_once("sim://?faults=service-request-after-ttt-zero,replies-after-retry")
    return {r["id"]: r for r in data["requirements"]}


def test_r_4_4_6_03_silence_after_a_request_taken_for_the_start_is_no_pass(late_pair) -> None:
    """0M1!'s '00002' met the retry and the request after it, '0<CR><LF>', was taken for
    0M1!'s reply: "no service request in 0.5 s after 0M1! -> '0<CR><LF>'" PASSed. That
    reply announced no ttt = 000 this time: INCONCLUSIVE."""
    found = late_pair["R-4.4.6-03"]
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # PASS before
    assert "no ttt = 000 announced" in found["findings"][0]["detail"]


def test_r_4_4_5_01_a_request_taken_too_soon_for_the_start_is_undecided(late_pair) -> None:
    """0MC1!'s '00002' met its retry; the request after it came 0.00 ms after the next try:
    "0MC1!: reply '0' does not have the form atttn" FAILed."""
    found = late_pair["R-4.4.5-01"]
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # FAIL before
    assert "too soon to answer it, and has a service request's words" in str(found["findings"])


def test_r_4_4_8_04_a_request_taken_late_for_d0_is_no_empty_reply(late_pair) -> None:
    """0M1!'s request came 29.33 ms after 0D0!, past the window a reply begins in; D0's values
    came 80 ms after it: "D0 returned no values although 2 were announced" FAILed."""
    found = late_pair["R-4.4.8-04"]
    assert found["verdict"] == "INCONCLUSIVE", found["findings"]  # FAIL before
    assert "past the window a reply begins in" in str(found["findings"])


def test_r_7_0_09_does_not_time_the_request_as_a_reply(late_pair) -> None:
    found = late_pair["R-7.0-09"]
    assert found["verdict"] == "PASS", found["findings"]  # FAIL before ('0.00 ms')
