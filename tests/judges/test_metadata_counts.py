"""``judges/metadata``'s counts on hand-made exchanges: the count an identify reply announces,
and R-6.2-07 INCONCLUSIVE (with its observations, so it outweighs another group's PASS) for
the groups whose count neither reply gives (issue 22, ninth round)."""

from __future__ import annotations

from conformance.judges.metadata import announced_count, uncounted_groups
from conformance.results import counted
from conformance.verdicts import Finding, Verdict, worst

from .test_judges import exchange


def test_the_identify_reply_s_count_is_read_where_its_form_allows():
    assert announced_count(exchange("0IM!", "00023\r\n", 0.0)) == 3
    assert announced_count(exchange("0IC!", "000212\r\n", 0.0)) == 12
    assert announced_count(exchange("0IM!", "0023\r\n", 0.0)) is None  # atttn short a digit
    assert announced_count(exchange("0IM!", "", 0.0)) is None  # no reply


def test_a_group_without_a_count_makes_the_rule_inconclusive_over_a_pass():
    groups = [(exchange("0M!", "0023\r\n", 0.0), exchange("0IM!", "0023\r\n", 1.0))]
    (found,) = uncounted_groups(groups)
    assert found.requirement == "R-6.2-07" and found.verdict is Verdict.INCONCLUSIVE
    assert found.observed == 1 and "0IM! -> '0023<CR><LF>'" in found.detail
    other = Finding("R-6.2-07", Verdict.PASS, "conforms", observed=276)
    assert worst(f.verdict for f in counted([other, found])) is Verdict.INCONCLUSIVE
    failed = Finding("R-6.2-07", Verdict.FAIL, "missing", observed=3, evidence=["0IC_002!"])
    assert worst(f.verdict for f in counted([failed, found])) is Verdict.FAIL
    assert uncounted_groups([]) == []
