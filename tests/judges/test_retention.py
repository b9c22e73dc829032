"""R-4.4.5-10's retention case judged over its D reads (``judges.retention.retained``).

continuous-overwrites-data + replies-after-retry (truth21): every D read, before and after
aR0!/aRC0!, was answered only 80 ms late, met by the retry, so the engine took no reply;
the case compared the two silences as "1 D replies identical" and PASSed the rule that
continuous-overwrites-data breaks. Hand-typed wire events, the first test failing on the
tree before (the case compared reply texts, '' with '')."""

from __future__ import annotations

from conformance.judges.retention import retained
from conformance.protocol import commands as cmds
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from conformance.verdicts import Verdict
from tests.support.hand_events import chars


def _read(t: float, reply: str | None) -> Exchange:
    """0D0! sent once at ``t``, answered ``reply`` 9 ms after it (None: silent)."""
    sent = chars(TOOL, "0D0!", t)
    got = chars(DUT, reply, sent[-1].end + 0.009) if reply else []
    end = got[-1].end if got else sent[-1].end + 0.03
    return Exchange(
        cmds.parse_command("0D0!"), "0D0!", [Attempt(None, sent, got, OK if got else NO_REPLY, end)]
    )


VALUES = "0+22.15+1013.2+45.7\r\n"


def test_two_unread_d0s_are_no_pass() -> None:
    found = retained([_read(0.0, None)], [_read(1.0, None)])
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "not compared" in found.detail


def test_values_kept_pass_and_values_lost_fail() -> None:
    assert retained([_read(0.0, VALUES)], [_read(1.0, VALUES)]).verdict is Verdict.PASS
    lost = retained([_read(0.0, VALUES)], [_read(1.0, "0\r\n")])
    assert lost.verdict is Verdict.FAIL and "changed from" in lost.detail


def test_a_pair_read_that_differs_fails_beside_an_unread_one() -> None:
    before = [_read(0.0, VALUES), _read(0.2, "0+1\r\n")]
    again = [_read(1.0, None), _read(1.2, "0\r\n")]
    found = retained(before, again)
    assert found.verdict is Verdict.FAIL and found.detail.startswith("D1 changed")


def test_an_empty_buffer_read_twice_is_no_pass() -> None:
    """Nothing a lost buffer would change: no check of the rule."""
    found = retained([_read(0.0, "0\r\n")], [_read(1.0, "0\r\n")])
    assert found.verdict is Verdict.INCONCLUSIVE and "no values read before" in found.detail
