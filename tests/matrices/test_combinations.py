"""The combination fault matrix (issue 18, part 7): the checking logic on made-up verdicts
(fast), and a CI-sized seeded selection of fault pairs run against the suite (marker
``matrix``). Combinations the measurement (notes/combos-result.md) found unexplained are
listed in :data:`conformance.matrices.combinations.KNOWN_OPEN` and expected to fail strictly,
so a fix flips them and the list must shrink."""

from __future__ import annotations

import pytest

from conformance.emulator.faults import conflicts
from conformance.emulator.faults.interactions import Interaction
from conformance.matrices.combinations import (
    CI_COMBINATIONS,
    KNOWN_OPEN,
    Finding,
    check,
    combo_port,
    combo_row,
    sample,
)

DECLARED = {"a": (("R-1",), ("R-2",)), "b": (("R-3",), ())}


def verdicts(**by_id: str) -> dict:
    reqs = [
        {
            "id": rid.replace("_", "-"),
            "verdict": v,
            "findings": [{"verdict": v, "detail": f"why {v}"}],
        }
        for rid, v in by_id.items()
    ]
    return {"requirements": reqs, "summary": {"verdict": "NON-COMPLIANT"}}


def test_flags_inside_the_union_are_clean():
    row = check(
        ("a", "b"), DECLARED, verdicts(R_1="FAIL", R_2="INCONCLUSIVE", R_3="WARN", R_9="PASS")
    )
    assert row.clean, row.explain()


def test_a_flag_outside_the_union_is_unexpected_with_its_detail():
    row = check(("a", "b"), DECLARED, verdicts(R_1="FAIL", R_3="FAIL", R_9="WARN"))
    assert [(f.requirement, f.verdict, f.detail) for f in row.unexpected] == [
        ("R-9", "WARN", "why WARN")
    ]
    assert not row.missed and not row.clean


def test_a_pass_on_a_members_requirement_is_a_missed_fail_counted_apart():
    row = check(("a", "b"), DECLARED, verdicts(R_1="PASS", R_2="PASS", R_3="FAIL"))
    assert [f.requirement for f in row.missed] == ["R-1", "R-2"]
    assert not row.unexpected


def test_an_error_is_never_clean():
    assert not check(("a", "b"), DECLARED, verdicts(R_1="FAIL", R_3="ERROR")).clean


def test_declared_interactions_add_and_remove_only_for_their_members():
    masks = Interaction(
        frozenset({"a", "b"}), "a silences the sensor b needs", adds=("R-9",), removes=("R-1",)
    )
    data = verdicts(R_1="PASS", R_3="FAIL", R_9="FAIL")
    assert check(("a", "b"), DECLARED, data, [masks]).clean
    other = Interaction(frozenset({"a", "c"}), "not this pair", adds=("R-9",), removes=("R-1",))
    row = check(("a", "b"), DECLARED, data, [other])
    assert [f.requirement for f in row.unexpected] == ["R-9"]
    assert [f.requirement for f in row.missed] == ["R-1"]


def test_an_interaction_without_reason_or_effect_is_refused():
    with pytest.raises(ValueError):
        Interaction(frozenset({"a", "b"}), " ", adds=("R-9",))
    with pytest.raises(ValueError):
        Interaction(frozenset({"a", "b"}), "why")
    with pytest.raises(ValueError):
        Interaction(frozenset(), "why", adds=("R-9",))


def test_one_fault_alone_adds_beside_any_partner_and_never_removes():
    """identify-sends-service-request's R-7.0-09 (a request that falls due while a command
    is on the line follows it at once) was declared three times, pair by pair (seeds 4120,
    4142, 4156), though any partner that moves the schedule can land it: declared once now.
    A mask is a partner's doing, so a fault alone may not remove: that would excuse every
    missed FAIL of its requirement in every combination."""
    timing = Interaction(frozenset({"a"}), "a's stray line lands where the schedule puts it",
                         adds=("R-9",))  # fmt: skip
    data = verdicts(R_1="FAIL", R_3="FAIL", R_9="FAIL")
    assert check(("a", "b"), DECLARED, data, [timing]).clean
    assert check(("a", "c"), {**DECLARED, "c": (("R-3",), ())}, data, [timing]).clean
    row = check(("b", "c"), {**DECLARED, "c": (("R-1",), ())}, data, [timing])  # no a
    assert [f.requirement for f in row.unexpected] == ["R-9"]
    with pytest.raises(ValueError, match="alone only adds"):
        Interaction(frozenset({"a"}), "why", removes=("R-1",))


def test_a_service_request_right_after_a_command_is_declared_nowhere():
    """identify-sends-service-request's request 0 ms after a command it fell due under was
    declared to break R-7.0-09 beside any partner; a request is no reply, and R-7.0-09,
    which times replies, no longer takes it for one (judges.wire._request_not_reply,
    truth19): nothing left to declare."""
    from conformance.emulator.faults.interactions import INTERACTIONS

    assert not [i for i in INTERACTIONS if "R-7.0-09" in i.adds]


def test_the_sampler_is_deterministic_distinct_and_version_consistent():
    first = sample(60, 3, seed=7)
    assert first == sample(60, 3, seed=7) != sample(60, 3, seed=8)
    assert len(set(first)) == 60 and all(len(c) == len(set(c)) == 3 for c in first)
    assert sample(10) == sample(40)[:10]  # a CI selection is a prefix of a longer run
    for combo in first:
        assert "faults=" + ",".join(combo) in combo_port(combo)


def test_an_incomplete_run_is_never_clean():
    """(seeds 4074 and 4076) a combination the sim port refuses (one member masks the other)
    ran nothing: its requirements all undecided, the row counted clean on no evidence."""
    data = verdicts(R_1="INCONCLUSIVE", R_3="N/A")
    data["summary"]["verdict"] = "INCOMPLETE"
    data["run"] = {"stop_reason": "sim faults cannot be combined: a masks b"}
    row = check(("a", "b"), DECLARED, data)
    assert not row.clean
    assert row.errors == (Finding("run", "INCOMPLETE", "sim faults cannot be combined: a masks b"),)


def test_the_sampler_draws_only_combinations_that_compose():
    """3 of the 200 rows seeds 4073-4076 drew were refused compositions, e.g.
    fewer-values-than-announced with more-values-than-announced (both replace the count)."""
    for seed, size in ((4074, 3), (4076, 2), (4063, 2), (4063, 3)):
        drawn = sample(60, size, seed)
        assert len(drawn) == 60 and not [c for c in drawn if conflicts(c)]


def test_the_known_open_list_names_only_ci_combinations():
    assert set(KNOWN_OPEN) <= set(CI_COMBINATIONS)


@pytest.mark.matrix
@pytest.mark.parametrize(
    "combo",
    [
        pytest.param(
            c, marks=pytest.mark.xfail(strict=True, reason=KNOWN_OPEN[c]) if c in KNOWN_OPEN else ()
        )
        for c in CI_COMBINATIONS
    ],
    ids=",".join,
)
def test_combination_flags_only_its_members_requirements_and_misses_none(combo):
    row = combo_row(combo)
    assert row.clean, row.explain()


def test_cli_prints_each_unexplained_row_and_totals_and_exits_1(monkeypatch, capsys):
    """``matrix --combinations``: the rows a (stubbed) run reports, totals, exit 1."""
    from conformance import cli
    from conformance.matrices import combinations
    from conformance.matrices.combinations import ComboRow, Finding

    def fake(combos, processes, progress):
        assert len(combos) == 2 and all(len(c) == 3 for c in combos)
        bad = Finding("R-4.3-04", "PASS", "silence after aA$!")
        return [
            ComboRow(combos[0], "NON-COMPLIANT", (), (bad,)),
            ComboRow(combos[1], "COMPLIANT", (), ()),
        ]

    monkeypatch.setattr(combinations, "combination_matrix", fake)
    code = cli.main(["matrix", "--combinations", "2", "--size", "3", "--seed", "5"])
    out = capsys.readouterr().out
    assert code == 1
    assert "missed FAIL: R-4.3-04 PASS: silence after aA$!" in out
    assert "1/2 combinations clean; 0 unexpected FAIL/WARN, 1 missed FAIL, 0 ERROR" in out


def test_cli_refuses_no_combinations():
    from conformance import cli

    assert cli.main(["matrix", "--combinations", "0"]) == 4


def test_a_pass_on_a_rule_a_member_leaves_undecided_unbroken_stands():
    """replies-after-retry leaves R-4.3-03 INCONCLUSIVE (its 80 ms replies run into the
    retries) but does not break it: beside wrong-crc every address 0-9 was answered on the
    wire, and the PASS was counted a missed FAIL (truth15). Declared by the other member
    too, the PASS is still missed; a rule the member breaks is missed whatever it says."""
    declared = {"late": (("R-7",), ("R-2",)), "b": (("R-3",), ()), "c": (("R-3",), ("R-2",))}
    unbroken = {"late": ("R-2", "R-7")}
    data = verdicts(R_7="FAIL", R_2="PASS", R_3="FAIL")
    assert check(("late", "b"), declared, data, unbroken=unbroken).clean
    assert not check(("late", "b"), declared, data, unbroken={}).clean  # before truth15
    row = check(("c", "late"), declared, data, unbroken=unbroken)
    assert [f.requirement for f in row.missed] == ["R-2"]
    row = check(("late", "b"), declared, verdicts(R_7="PASS", R_3="FAIL"), unbroken=unbroken)
    assert [f.requirement for f in row.missed] == ["R-7"]


def test_a_combination_runs_in_the_version_a_member_names():
    """v13-concurrent-over-20 sorted after a v1.4 fault ran in a v1.4 profile (the first
    member's), where 25 values for aC! are allowed: R-4.4.7-03 PASSed, read as missed."""
    assert combo_port(("service-request-after-ttt-zero", "v13-concurrent-over-20")).endswith(
        "&version=1.3"
    )  # 1.4 before
    assert combo_port(("inter-char-gap", "service-request-after-ttt-zero")).endswith("&version=1.4")


def test_members_that_cannot_be_one_sensor_are_an_inconclusive_row_not_an_error():
    """replies-after-retry beside response-too-early, response-too-late or
    break-before-reply: both set reply_delay, the sim refuses the port, and the row was an
    ERROR (INCOMPLETE) although the tool did not fail (truth21). Not run: INCONCLUSIVE,
    naming why, and never clean."""
    from conformance.matrices.combinations import combo_row

    for other in ("break-before-reply", "response-too-early", "response-too-late"):
        row = combo_row(("replies-after-retry", other))
        assert row.verdict == "INCONCLUSIVE" and not row.errors and not row.clean, row
        assert "both set reply_delay" in row.refused
        assert "INCONCLUSIVE, not run: cannot be one sensor" in row.explain()
    # a member that needs what the version's profile lacks: refused by the sim alike
    row = combo_row(("multiline-slow-lines", "v13-concurrent-over-20"))
    assert row.verdict == "INCONCLUSIVE" and not row.errors and not row.clean, row
    assert "needs XHELP, which a v1.3 sensor does not have" in row.refused
