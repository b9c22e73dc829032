"""A service request sent on its own right after the tool's aD0! is not that D0's reply
(``judges.late_before.service_request_too_soon``): service-request-after-ttt-zero beside
inter-char-gap put its '0<CR><LF>' at the end of the tool's 0D0!, 8 ms before the real D0
reply with the two announced values, and R-4.4.8-03/-04 FAILed "0 values were returned for
2 announced". The service request's own rule still FAILs; the data rules are undecided
there, and R-7.0-09, which times replies, does not time the request (truth19: it FAILed
"0.00 ms" on it, a false FAIL, judges.wire._request_not_reply)."""

from __future__ import annotations

import pytest

from conformance.conduct import run_once


@pytest.fixture(scope="module")
def verdicts() -> dict[str, dict]:
    data = run_once("sim://?faults=service-request-after-ttt-zero,inter-char-gap")
    return {r["id"]: r for r in data["requirements"]}


def test_the_service_request_is_not_taken_for_d0s_empty_reply(verdicts):
    for rid in ("R-4.4.8-01", "R-4.4.8-03", "R-4.4.8-04"):
        assert verdicts[rid]["verdict"] != "FAIL", verdicts[rid]["findings"]
        assert any(
            "too soon to answer it, and has a service request's words" in f["detail"]
            for f in verdicts[rid]["findings"]
        ), rid


def test_the_deviations_on_the_wire_still_fail(verdicts):
    assert verdicts["R-4.4.6-03"]["verdict"] == "FAIL"
    assert verdicts["R-7.0-09"]["verdict"] == "PASS"  # a request is no reply (truth19)
    assert verdicts["R-7.0-12"]["verdict"] == "FAIL"  # inter-char-gap's own
