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
