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
    (found,) = uncounted_groups(groups, ("R-6.2-07",))
    assert found.requirement == "R-6.2-07" and found.verdict is Verdict.INCONCLUSIVE
    assert found.observed == 1 and "0IM! -> '0023<CR><LF>'" in found.detail
    other = Finding("R-6.2-07", Verdict.PASS, "conforms", observed=276)
    assert worst(f.verdict for f in counted([other, found])) is Verdict.INCONCLUSIVE
    failed = Finding("R-6.2-07", Verdict.FAIL, "missing", observed=3, evidence=["0IC_002!"])
    assert worst(f.verdict for f in counted([failed, found])) is Verdict.FAIL
    assert uncounted_groups([], ("R-6.2-07",)) == []


def test_every_record_rule_is_inconclusive_for_a_group_never_read():
    """metadata-too-long + measure-ttt-two-digits (+ abort-keeps-old-data, seed 4118): aM!'s
    count unreadable, its too-long record never asked for, and R-6.2-04 PASSed on the other
    groups' 276 records. Every rule over a group's records is INCONCLUSIVE for it (only the
    rules the case judges)."""
    groups = [(exchange("0M!", "0023\r\n", 0.0), exchange("0IM!", "0023\r\n", 1.0))]
    ids = ("R-6.2-01", "R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2-07", "R-6.2.1-01", "R-6.2.2-01")
    found = uncounted_groups(groups, ids)
    assert {f.requirement for f in found} == set(ids) - {"R-6.2-01"}
    assert all(f.verdict is Verdict.INCONCLUSIVE and f.observed == 1 for f in found)
    other = Finding("R-6.2-04", Verdict.PASS, "conforms", observed=276)
    too_long = [f for f in found if f.requirement == "R-6.2-04"]
    assert worst(f.verdict for f in counted([other, *too_long])) is Verdict.INCONCLUSIVE
    assert [f.requirement for f in uncounted_groups(groups, ("R-6.2-04",))] == ["R-6.2-04"]
