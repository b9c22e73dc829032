"""The turnaround after a reply that closed its exchange counts from the latest its last
character can have ended on the wire (:meth:`Link.received_by`), not from a stamp the link
placed later than that (issue 22, usb12: behind ``--echo --usb-latency 16`` the stamps of a
reply's last character lay 0-16 ms past its arrival, and every such turnaround waited that
much more). Where the look applies (a rule reads what the sensor sends next), the stamp
stays the base, as the look's figure was drawn from the stamps.

The sim link stands in for a real one whose last stamp lies ``PUSHED`` past the arrival."""

from __future__ import annotations

import pytest

from conformance.protocol.timing import RELEASE_LINE, TOLERANCE
from tests.tool_recorder.test_look_after_line_end import (
    CLOSED,
    LOOK,
    LOOKED_AFTER,
    TURNAROUND,
    _marking_before_next,
    _real_like,
)

PUSHED = 6e-3


def _pushed(script: dict[str, str]):
    master = _real_like(script)
    master.link.received_by = lambda end: end - PUSHED  # type: ignore[method-assign]
    return master


@pytest.mark.parametrize("command", ["0I!", "0D0!", "0!", "0A1!"])
def test_after_a_closed_reply_the_turnaround_counts_from_the_arrival(command):
    master = _pushed({command: CLOSED[command]})
    marking = _marking_before_next(master, command)  # from the LF's stamp
    assert marking == pytest.approx(TURNAROUND - PUSHED, abs=1e-12)
    # from where the LF ended at the latest, the sensor's 7.5 (+0.4) ms are still its own
    assert marking + PUSHED >= RELEASE_LINE + TOLERANCE


@pytest.mark.parametrize("command", ["0M!", "0C!", "0XSET!"])
def test_where_the_look_applies_the_stamp_stays_the_base(command):
    master = _pushed({command: LOOKED_AFTER[command]})
    assert _marking_before_next(master, command) == pytest.approx(TURNAROUND + LOOK, abs=1e-12)


def test_a_link_that_knows_no_better_keeps_the_stamp():
    master = _real_like({"0I!": CLOSED["0I!"]})
    assert _marking_before_next(master, "0I!") == pytest.approx(TURNAROUND, abs=1e-12)
