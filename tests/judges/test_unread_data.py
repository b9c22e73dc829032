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


def test_an_empty_reply_with_its_crc_past_d9_is_no_refusal_of_the_index():
    """R-5.1-02 FAILs text ('0UNKN') to aD10! after aHA!, as it does silence (seed 4090);
    the empty form with aHA!'s CRC ('0' + CRC) is no such text. The first version took any
    character after the address but a sign for text, so '0' + CRC FAILed."""
    from conformance.judges.measurements import data_violations
    from conformance.judges.tally import Tally
    from conformance.protocol.crc import ascii_crc

    def verdict(d10: str) -> Verdict:
        m = started("0HA!", "0000011\r\n", 11)
        replies = [f"0+{i}{ascii_crc(f'0+{i}')}\r\n" for i in range(10)]
        m.data = [exchange(f"0D{i}!", reply, 1.0 + i) for i, reply in enumerate(replies)]
        m.data.append(exchange("0D10!", d10, 11.0))
        tally = Tally(("R-5.1-02",))
        data_violations(m, tally)
        (finding,) = tally.findings("conforms")
        return finding.verdict

    assert verdict("0UNKN\r\n") is Verdict.FAIL
    assert verdict(f"0{ascii_crc('0')}\r\n") is not Verdict.FAIL
