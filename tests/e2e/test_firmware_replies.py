"""Support read from well-formed answers only (issue 18): an error text such as '5UNKN' is
no continuous measurement, 'a00000' to aC! is no concurrent one, and the deviation is one
root whose consequences name it."""

from __future__ import annotations

import pytest

from conformance.conduct import run_once
from conformance.judges.support import serves_continuous, text_instead_of_values, values_of
from tests.judges.test_judges import exchange


@pytest.mark.parametrize(
    ("reply", "values", "text"),
    [
        ("0+22.1+45.6\r\n", ["+22.1", "+45.6"], False),
        ("0+22.1IoD\r\n", ["+22.1"], False),  # an RC reply: its CRC is no value
        ("0\r\n", [], False),  # the empty reply of an index not served
        ("0UNKN\r\n", [], True),  # firmware's text for what it does not serve
        ("0ERR+1\r\n", [], False),  # text before a sign: no values (its format is judged)
    ],
)
def test_values_only_from_a_values_reply(reply, values, text):
    ex = exchange("0R2!", reply, 1.0)
    assert values_of(ex) == values
    assert serves_continuous(ex) is bool(values)
    assert text_instead_of_values(ex) is text


def test_empty_crc_reply_is_not_text():
    assert not text_instead_of_values(exchange("0RC2!", "0AP@\r\n", 1.0), crc=True)


def _verdicts(port: str) -> dict[str, dict]:
    return {r["id"]: r for r in run_once(port)["requirements"]}


def test_unknown_command_text_is_not_support_and_is_one_root():
    """Before: R-4.4.8.1-02 FAILed 'R9 gave no values' (the text read as support), and
    R-4.4.12-03/-05 and R-6.2-06 FAILed on the text; the undefined groups' FAILs stood
    alone."""
    v = _verdicts("sim://?faults=unknown-command-text")
    assert v["R-4.4.8.1-03"]["verdict"] == "FAIL"
    assert v["R-4.4.8.1-02"]["verdict"] != "FAIL"
    for rid in ("R-4.4.12-03", "R-4.4.12-05", "R-6.2-06", "R-4.4.8.1-01"):
        assert v[rid]["verdict"] not in ("FAIL", "WARN"), rid
    for rid in ("R-4.4.5-01", "R-4.4.7-01"):
        assert v[rid]["verdict"] == "FAIL"
        assert v[rid]["consequence_of"] == "R-4.4.8.1-03"


def test_a00000_to_ac_is_not_support():
    """Before: R-4.4.7-08 PASSed "aC! answered '000000'" and R-4.4.7-01/-03 counted 0C!."""
    v = _verdicts("sim://?faults=concurrent-zero")
    assert v["R-4.4.7-02"]["verdict"] == "FAIL"
    assert v["R-4.4.7-08"]["verdict"] == "FAIL"
    assert v["R-4.4.7-08"]["consequence_of"] == "R-4.4.7-02"
    for rid in ("R-4.4.7-01", "R-4.4.7-03"):
        for f in v[rid]["findings"]:
            assert "0C!," not in f["detail"] and "0CC!," not in f["detail"], rid


def test_pulse_needs_a_sensor_shown_in_standby():
    """Before: a sensor that never sleeps answered after the 5 ms pulse, R-7.0-03 FAIL with
    no link; the pulse judges only a sensor shown in standby."""
    v = _verdicts("sim://?faults=never-standby")
    assert v["R-7.0-15"]["verdict"] == "FAIL"
    assert v["R-7.0-03"]["verdict"] == "INCONCLUSIVE"
    assert v["R-7.0-03"]["consequence_of"] == "R-7.0-15"
    assert "precondition not met" in v["R-7.0-03"]["findings"][0]["detail"]


def test_pulse_still_fails_a_sensor_in_standby_that_wakes_on_it():
    v = _verdicts("sim://?faults=wakes-on-short-spacing")
    assert v["R-7.0-03"]["verdict"] == "FAIL"


def test_text_after_an_abort_is_no_service_request():
    """Before: '00000' sent unasked after the break FAILed R-4.4.5.1-01 "a service request
    arrived after the break" (its first '0' read as one); a service request is exactly
    a<CR><LF>, and the text breaks the rule against sending unasked."""
    v = _verdicts("sim://?faults=abort-sends-zero-reply")
    assert v["R-4.4.5.1-01"]["verdict"] == "PASS"
    assert v["R-4.4.5-08"]["verdict"] == "FAIL"
    assert any("unasked" in f["detail"] for f in v["R-4.4.5-08"]["findings"])


def test_malformed_address_change_is_followed_not_blamed(monkeypatch):
    """Before: a sensor that took the malformed '0A1M!' as '0A1!' answered '1' and the
    exploration broke R-4.3-01 ("starts with '1', not the address"); decision A12 makes a
    reply to a malformed command informative, and the tool follows and undoes the change."""
    from dataclasses import replace

    from hypothesis import strategies as st

    from conformance.ports import open_sim, parse_sim
    from conformance.sensor import exploration
    from conformance.sensor.session import SensorSession

    opened = open_sim(parse_sim("sim"))
    device = opened.devices[0]
    device.behaviour = replace(device.behaviour, address_change_ignores_tail=True)
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    monkeypatch.setattr(exploration, "JUNK", st.just("A1M"))
    record = exploration.explore(session)  # the default sequences: malformed steps among them
    assert record.broken is None
    assert any("decision A12" in line for line in record.log)
    assert device.address == "0"
    assert any("restored" in note for note in session.address_notes)
