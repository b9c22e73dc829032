"""judges.measurements.unread_data on hand-made records: a start reply in digits that gives
no count hides values nobody asked for (R-4.4.8-02 and the other D-reply rules are
INCONCLUSIVE then); a reply of zeros or of text hides none."""

from __future__ import annotations

import pytest

from conformance.judges.measurements import unread_data
from conformance.judges.support import unreadable_count
from conformance.tool_recorder.records import Measurement
from conformance.verdicts import Verdict
from tests.judges.test_judges import exchange


def started(command: str, reply: str, count: int | None = None) -> Measurement:
    start = exchange(command, reply, 0.0)
    return Measurement(start.command, start, count=count)


@pytest.mark.parametrize(
    ("reply", "count", "unread"),
    [
        ("0023\r\n", None, True),  # atttn with a two-digit ttt: values unknown, never read
        ("0003020\r\n", None, True),  # a three-digit count to aC!
        ("0000\r\n", None, False),  # zeros only: no values however it is read
        ("0UNKN\r\n", None, False),  # text: no measurement reply at all
        ("", None, False),  # silence: nothing started
        ("00013\r\n", 3, False),  # a count: its D replies were read
    ],
)
def test_a_start_reply_hides_values_only_in_unreadable_digits(reply, count, unread):
    assert unreadable_count(started("0M!", reply, count)) is unread


def test_the_rules_asked_are_inconclusive_citing_every_unread_start():
    ms = [started("0M!", "0023\r\n"), started("0M3!", "0000\r\n"), started("0V!", "0013\r\n")]
    findings = unread_data(ms, ("R-4.4.8-02", "R-4.4-05"))
    assert [(f.requirement, f.verdict) for f in findings] == [
        ("R-4.4.8-02", Verdict.INCONCLUSIVE),
        ("R-4.4-05", Verdict.INCONCLUSIVE),
    ]
    assert findings[0].observed == 2
    assert "0M!" in findings[0].detail and "0V!" in findings[0].detail
    assert "0M3!" not in findings[0].detail


def test_nothing_when_every_start_reply_was_read():
    assert unread_data([started("0M!", "00013\r\n", 3)], ("R-4.4.8-02",)) == []
