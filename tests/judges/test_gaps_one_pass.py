"""R-7.0-12 (issue 22): the character gaps of a run without local irregularity are observed in
one pass, grouped as they are made (``wire._observe_gaps_alike`` -> ``timing.Observed``), and
``combine_local`` reads the groups instead of passing over every observation again. The
finding is the one the multi-pass path gives over the same observations as a plain list:
verdict, detail, figures, distribution, for random gap sequences with ties, signed zeros,
NaN and gaps on and around the limit."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import wire
from conformance.judges.timing import Alike, Observed, combine, combine_local, distribution

gap_values = st.sampled_from(
    [0.0, -0.0, math.nan, 0.3e-3, 1.66e-3, 1.7e-3, 1.9e-3, 2.06e-3, 2.5e-3, -1e-3]
) | st.floats(-1e-3, 3e-3, allow_nan=False)
wheres = st.sampled_from(["in reply to 0D0!", "in reply to 0M!", "in reply to 1D0!"])


@st.composite
def gap_sequences(draw):
    """Gaps as ``_cut_gaps`` gives them, drawn from few values so that many tie."""
    pool = draw(st.lists(st.tuples(gap_values, wheres), min_size=1, max_size=8))
    picks = draw(st.lists(st.integers(0, len(pool) - 1), min_size=0, max_size=300))
    return [(pool[i][0], pool[i][1], None, None, ("0D0!", "0+1", k)) for k, i in enumerate(picks)]


def _seen(found) -> str:
    """All a finding says, NaN included (``nan != nan`` would fail an equality)."""
    return repr(found)


@settings(max_examples=400, deadline=None)
@given(gap_sequences(), st.sampled_from([0.0, 1e-5, 0.4e-3]), st.booleans(), st.booleans())
def test_r_7_0_12_one_pass_groups_give_the_multi_pass_finding(gaps, base, real_time, smallest):
    observed = wire._observe_gaps_alike(gaps, base)
    assert type(observed) is Observed
    plain = list(observed)  # the same observations, read the multi-pass way
    # the groups are each distinct object first where it first comes, and how often it comes
    firsts = list({id(o[0]): o[0] for o in plain}.values())
    assert observed.distinct == firsts and all(
        a is b for a, b in zip(observed.distinct, firsts, strict=True)
    )
    assert observed.counts == [sum(o[0] is m for o in plain) for m in firsts]
    assert sum(observed.counts) == len(plain)
    grouped = combine_local(
        "R-7.0-12", observed, "character gap", real_time=real_time, smallest_is_worst=smallest
    )
    again = combine_local(
        "R-7.0-12", plain, "character gap", real_time=real_time, smallest_is_worst=smallest
    )
    assert _seen(grouped) == _seen(again)


@settings(max_examples=200, deadline=None)
@given(gap_sequences(), st.sampled_from([0.0, 0.4e-3]))
def test_r_7_0_12_alike_reads_as_the_findings_one_by_one(gaps, base):
    observed = wire._observe_gaps_alike(gaps, base)
    alike = Alike(observed)
    findings = [o[0] for o in observed]
    assert len(alike) == len(findings) and list(alike) == findings
    assert alike[:3] == findings[:3]
    if findings:
        assert alike[-1] is findings[-1]
    assert _seen(distribution(alike)) == _seen(distribution(findings))
    assert _seen(combine("R-7.0-12", alike, "gap")) == _seen(combine("R-7.0-12", findings, "gap"))


@given(st.lists(st.integers(1, 4), max_size=6))
def test_a_counted_fold_reads_by_index_as_in_order(counts):
    """Observed not placed (memory24), and its Alike: by index, negative index and slice, the
    objects each ``counts`` times in the order each first came, as iterating gives them."""
    observed = Observed(placed=False)
    for k, count in enumerate(counts):
        observed.distinct.append(f"m{k}")  # type: ignore[arg-type]
        observed.counts.append(count)
        for _ in range(count):
            observed.observe(k, None)
    alike, one_by_one = Alike(observed), list(observed)
    assert [o[0] for o in one_by_one] == [f"m{k}" for k, c in enumerate(counts) for _ in range(c)]
    n = len(one_by_one)
    for i in [*range(n), *range(-n, 0)]:
        assert observed[i] == one_by_one[i] and alike[i] == one_by_one[i][0]
    assert observed[1:-1] == one_by_one[1:-1] and alike[::2] == [o[0] for o in one_by_one][::2]
    for bad in (n, -n - 1):
        with pytest.raises(IndexError):
            observed[bad]
        with pytest.raises(IndexError):
            alike[bad]
