"""Which replies to ``a!`` show a sensor that answers ``a!`` (``ToolRecorder.acknowledged``).

An ENG20009 Arduino Due sketch (docs/kit.md, thirty-fourth round) answers no ``a!``; every
reply it gives comes 100 ms after the command, and its ``aRn!`` gives two lines 100 ms apart.
The second line of ``0R2!``'s reply, '0+1013.25', began 3 ms after an ``a!`` retry and was
taken as that ``a!``'s reply: the engine counted the sensor as one that answers ``a!``, so
its silence to ``a!`` at a new address FAILed R-4.4.4-03, the restore checked with ``a!``
("COULD NOT restore") and the run stopped. A reply with signed values is no acknowledgement,
valid or not; a malformed one without values (ack-trailing-space's '0 ') still is.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.emulator.faults import FaultSet
from conformance.emulator.replies import ReplyKind
from conformance.ports import open_sim, parse_sim
from conformance.tool_recorder import ToolRecorder
from conformance.tool_recorder.engine import carries_values


@pytest.mark.parametrize(
    ("text", "values"),
    [
        ("0+1013.25\r\n", True),
        ("0-4.5+2\r\n", True),
        ("0\r\n", False),
        ("0 \r\n", False),
        ("00013\r\n", False),  # a start reply's digits are no signed values
        ("0+\r\n", False),  # a sign without a digit
        ("", False),
    ],
)
def test_carries_values(text, values):
    assert carries_values(text) is values


def _acknowledged_after(monkeypatch, body: str) -> set[str]:
    """``acknowledged`` after one ``0!`` to a simulated sensor whose a! reply is ``body``."""
    usual = FaultSet.rewrite

    def rewrite(self, reply):
        if reply.kind is ReplyKind.ACKNOWLEDGE:
            return replace(reply, body=body)
        return usual(self, reply)

    monkeypatch.setattr(FaultSet, "rewrite", rewrite)
    master = ToolRecorder(open_sim(parse_sim("sim://")).link)
    ex = master.acknowledge("0")
    assert ex.answered and ex.reply_text.startswith(body)
    return master.acknowledged


def test_a_data_line_taken_for_the_a_reply_is_no_acknowledgement(monkeypatch):
    assert _acknowledged_after(monkeypatch, "0+1013.25") == set()  # {'0'} at base-s69


def test_a_malformed_acknowledgement_still_shows_a_sensor_that_answers_a(monkeypatch):
    assert _acknowledged_after(monkeypatch, "0 ") == {"0"}
