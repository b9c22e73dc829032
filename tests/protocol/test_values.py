"""The value grammar (R-4.4.8-02, decision A13) and D-reply packing (R-4.4.8.3-01/-03)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol.values import (
    Violation,
    check_value,
    errors,
    format_value,
    pack_values,
    split_values,
)


@pytest.mark.parametrize(
    ("text", "values"),
    [
        ("+1.23-4.5+6", ["+1.23", "-4.5", "+6"]),
        ("", []),
        ("+3.14", ["+3.14"]),
        ("-0.00045+2.223", ["-0.00045", "+2.223"]),
        ("1.23+4", ["1.23", "+4"]),  # text before the first sign is kept, not dropped
        ("++1", ["+", "+1"]),
        ("+1..2-", ["+1..2", "-"]),
    ],
)
def test_split_values(text: str, values: list[str]) -> None:
    assert split_values(text) == values
    assert "".join(split_values(text)) == text


@pytest.mark.parametrize(
    "value",
    ["+0", "-1", "+3.14", "-0.00045", "+1234567", "-1234567", "+123456.7", "+0.123456", "+12354"],
)
def test_clean_values(value: str) -> None:
    assert check_value(value) == []


@pytest.mark.parametrize(
    ("value", "fragment"),
    [
        ("1.5", "sign"),
        ("", "sign"),
        (".5", "sign"),
        ("+", "no digit"),
        ("-.", "no digit"),
        ("+1.2.3", "more than one decimal point"),
        ("+12345678", "8 digits"),
        ("+1234567.8", "8 digits"),
        ("+1e5", "non-numeric"),
        ("+1 ", "non-numeric"),
        ("+1,5", "non-numeric"),
        ("+\x7f", "non-numeric"),
    ],
)
def test_hard_grammar_failures(value: str, fragment: str) -> None:
    found = check_value(value)
    assert found, value
    assert all(v.requirement == "R-4.4.8-02" and not v.warning for v in found)
    assert any(fragment in v.message for v in found)


def test_more_than_nine_characters() -> None:
    """Nine characters is the most a legal value can reach; a tenth is reported on its own."""
    found = check_value("+1.2.3.4.5")
    assert any("10 characters" in v.message for v in found)


def test_messages_escape_the_offending_text() -> None:
    (violation,) = check_value("+1\x02")
    assert "<STX>" in violation.message and "\x02" not in violation.message


@pytest.mark.parametrize(
    ("value", "fragment"),
    [
        ("+.5", "no digit before"),
        ("+5.", "ends with '.'"),
        ("-0", "negative zero"),
        ("-0.000", "negative zero"),
        ("+05", "leading zero"),
        ("+00.5", "leading zero"),
        ("+0000007", "leading zero"),
    ],
)
def test_decision_a13_warnings(value: str, fragment: str) -> None:
    found = check_value(value)
    assert found and errors(found) == []
    assert all(v.requirement == "R-4.4.8-02" and v.warning for v in found)
    assert any(fragment in v.message for v in found)


def test_leading_zeros_count_towards_seven_digits() -> None:
    assert errors(check_value("+00000001"))  # eight digits, the zeros count


def test_errors_filters_warnings() -> None:
    hard, soft = Violation("R-x", "a"), Violation("R-y", "b", warning=True)
    assert errors([hard, soft]) == [hard]


# -- format_value ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("x", "decimals", "text"),
    [
        (0, None, "+0"),
        (-42, None, "-42"),
        (1234567, None, "+1234567"),
        (3.14, None, "+3.14"),
        (-2.5, None, "-2.5"),
        (0.1 + 0.2, None, "+0.3"),
        (1234567.89, None, "+1234568"),
        (0.00045, None, "+0.00045"),
        (1e-9, None, "+0"),
        (-1e-9, None, "+0"),
        (-0.0, None, "+0"),
        (2.0, None, "+2"),
        (2.718, 3, "+2.718"),
        (2.0, 2, "+2.00"),
        (-0.001, 2, "+0.00"),
        (7.5, 0, "+8"),
        ("+3.14", None, "+3.14"),
    ],
)
def test_format_value(x: float | int | str, decimals: int | None, text: str) -> None:
    assert format_value(x, decimals) == text
    assert check_value(text) == []


@pytest.mark.parametrize(
    ("x", "decimals"),
    [
        (12345678, None),
        (-12345678, None),
        (9999999.6, None),
        (12345678.0, None),
        (math.nan, None),
        (math.inf, None),
        (1.0, -1),
        (123456.7, 2),
        ("3.14", None),
        ("+.5", None),  # legal with a warning, but not clean emulator output
        (True, None),
    ],
)
def test_format_value_rejects(x: float | int | str, decimals: int | None) -> None:
    with pytest.raises(ValueError):
        format_value(x, decimals)


finite = st.floats(min_value=-9_999_999, max_value=9_999_999, allow_nan=False)


@given(finite)
def test_formatted_floats_are_clean_and_close(x: float) -> None:
    try:
        text = format_value(x)
    except ValueError:
        assert abs(round(x)) >= 9_999_999.5 - 1  # only values that round past 7 digits
        return
    assert check_value(text) == []
    digits_before_point = len(str(int(abs(x)))) if abs(x) >= 1 else 1
    assert abs(float(text) - x) <= 0.5 * 10 ** -(7 - digits_before_point) + 1e-9


@given(st.lists(st.one_of(st.integers(-9_999_999, 9_999_999), finite), max_size=20))
def test_format_then_split_round_trips(xs: list[float | int]) -> None:
    texts = []
    for x in xs:
        try:
            texts.append(format_value(x))
        except ValueError:
            continue
    assert split_values("".join(texts)) == texts


# -- pack_values -----------------------------------------------------------------------------
def test_pack_values_spec_example_c() -> None:
    """4.4.8.4 c: nine values after aM! need D0 and D1 under the 35-character limit.

    The example's sensor puts six values in D0; greedy packing fits seven (exactly 35
    characters), which R-4.4.8.3-03 prefers.
    """
    values = split_values("+1.11+2.22+3.33+4.44+5.55+6.66+7.77+8.88+9.99")
    assert pack_values(values, 35) == ["+1.11+2.22+3.33+4.44+5.55+6.66+7.77", "+8.88+9.99"]
    assert pack_values(values, 75) == ["".join(values)]


def test_pack_values_edges() -> None:
    assert pack_values([], 35) == []
    assert pack_values(["+1", "+2"], 4) == ["+1+2"]
    assert pack_values(["+1", "+2", "+3"], 4) == ["+1+2", "+3"]
    with pytest.raises(ValueError):
        pack_values(["+123456789"], 5)


value_text = st.builds(
    lambda sign, digits: sign + digits,
    st.sampled_from("+-"),
    st.text("0123456789", min_size=1, max_size=7),
)


@given(st.lists(value_text, max_size=40), st.sampled_from([35, 75]))
def test_pack_values_never_splits_and_fills_greedily(values: list[str], limit: int) -> None:
    groups = pack_values(values, limit)
    assert "".join(groups) == "".join(values)
    assert [v for g in groups for v in split_values(g)] == values  # no value cut in two
    assert all(0 < len(g) <= limit for g in groups)
    for group, following in zip(groups, groups[1:], strict=False):
        assert len(group) + len(split_values(following)[0]) > limit  # R-4.4.8.3-03
