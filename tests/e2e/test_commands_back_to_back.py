"""A recorder's commands back to back, each ending in its '!' with no break between them.

A command ends at its '!' (4.4): what begins with an address right after it is the next
command, to whichever sensor it names. The view read ``9!0I!`` (an acknowledge to a spare
address, then at once the identification to the sensor at '0') as one transmission, so
R-4.4-04 FAILed "'!' is not exactly the last character" on a recorder whose every command
ended in its only '!', and R-7.0-17 judged a command '9!0I!' rather than the '0I!' sent to a
new sensor with no break (``conformance.view.segments._cut``)."""

from __future__ import annotations

import pytest

from conformance.conduct import run_once


@pytest.fixture
def acknowledge_before_identify(monkeypatch):
    """The golden recorder, every ``0I!`` written as ``9!0I!``: ``9!`` to a spare address,
    then ``0I!`` with no break (the sensor at '0', sent to standby by ``9!``, ignores it)."""
    from conformance.tool_recorder import engine

    encode = engine.encode_7e1
    monkeypatch.setattr(
        engine, "encode_7e1", lambda text: encode("9!" + text if text == "0I!" else text)
    )


def test_another_address_right_after_a_bang_is_a_new_command_r_4_4_04_r_7_0_17(
    acknowledge_before_identify,
):
    data = run_once("sim", role="recorder", keyword="test_command_text or test_break_when_due")
    found = {r["id"]: r for r in data["requirements"]}
    text = found["R-4.4-04"]
    assert text["verdict"] == "PASS", text["findings"]
    assert "9!0I!" not in str(text["findings"]), text["findings"]
    due = found["R-7.0-17"]
    assert due["verdict"] == "FAIL", due["findings"]
    assert "9!0I!" not in str(due["findings"]), due["findings"]
