"""ASCII response parsers: every rejection path names its requirement ID."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol import commands as c
from conformance.protocol.crc import ascii_crc
from conformance.protocol.responses import (
    MeasurementReply,
    Violation,
    check_address,
    check_address_reply,
    check_change_address_reply,
    check_data_sequence,
    check_measurement_count,
    expected_value_limit,
    is_service_request,
    measurement_digits,
    parse_data_reply,
    parse_data_reply_for,
    parse_ident,
    parse_measurement_reply,
    parse_measurement_reply_for,
    parse_metadata_reply,
    split_line,
)
from conformance.protocol.values import format_value, pack_values


def ids(violations: list[Violation]) -> list[str]:
    return [v.requirement for v in violations]


def hard(violations: list[Violation]) -> list[str]:
    return [v.requirement for v in violations if not v.warning]


def with_crc(text: str) -> str:
    return text + ascii_crc(text)


# -- split_line ------------------------------------------------------------------------------
def test_split_line_clean() -> None:
    assert split_line("0+3.14\r\n") == ("0+3.14", [])
    assert split_line("0\r\n") == ("0", [])


@pytest.mark.parametrize(
    ("raw", "body"),
    [("0+1", "0+1"), ("0+1\r", "0+1"), ("0+1\n", "0+1"), ("0+1\n\r", "0+1\n"), ("", "")],
)
def test_split_line_missing_terminator(raw: str, body: str) -> None:
    got, found = split_line(raw)
    assert got == body
    assert "R-4.2-03" in ids(found)


def test_split_line_too_short() -> None:
    body, found = split_line("\r\n")
    assert body == "" and ids(found) == ["R-4.2-03"]


@pytest.mark.parametrize("raw", ["0+1\x00\r\n", "0\t+1\r\n", "0+1\r\n\r\n", "0+1\x7f\r\n"])
def test_split_line_non_printable(raw: str) -> None:
    _, found = split_line(raw)
    assert ids(found) == ["R-4.2-02"]
    assert "\x00" not in found[0].message and "\r" not in found[0].message


def test_split_line_exempts_0x7f_only_in_crc_positions() -> None:
    raw = "0+1@\x7f\x7f\r\n"
    assert split_line(raw, crc_positions=3) == ("0+1@\x7f\x7f", [])
    assert ids(split_line(raw)[1]) == ["R-4.2-02"]
    assert ids(split_line("0\x7f+1AAA\r\n", crc_positions=3)[1]) == ["R-4.2-02"]
    assert ids(split_line("0+1@\x01\x7f\r\n", crc_positions=3)[1]) == ["R-4.2-02"]


# -- addresses -------------------------------------------------------------------------------
def test_check_address() -> None:
    assert check_address("0+1") == []
    assert check_address("0+1", "0") == []
    assert ids(check_address("")) == ["R-4.3-01"]
    assert ids(check_address("#+1")) == ["R-4.3-04"]
    assert ids(check_address("?")) == ["R-4.3-04"]
    assert ids(check_address("1+1", "0")) == ["R-4.3-01"]


@pytest.mark.parametrize("requirement", ["R-4.4.1-01", "R-4.4.3-01", "R-4.4.4-01"])
def test_check_address_reply(requirement: str) -> None:
    assert check_address_reply("5", "5", requirement) == []
    assert check_address_reply("5", None, requirement) == []
    assert ids(check_address_reply("5", "0", requirement)) == ["R-4.3-01"]
    assert ids(check_address_reply("01", "0", requirement)) == [requirement]
    assert requirement in ids(check_address_reply("", "0", requirement))


def test_check_change_address_reply() -> None:
    assert check_change_address_reply("3", "0", "3") == []
    assert check_change_address_reply("0", "0", "3") == []  # refused: old address comes back
    assert ids(check_change_address_reply("5", "0", "3")) == ["R-4.4.4-01"]
    assert ids(check_change_address_reply("3\r", "0", "3")) == ["R-4.4.4-01"]
    assert ids(check_change_address_reply("#", "0", "3")) == ["R-4.3-04"]


def test_service_request() -> None:
    assert is_service_request("0", "0")
    assert not is_service_request("1", "0")
    assert not is_service_request("0+1", "0")
    assert not is_service_request("", "0")


# -- aI! -------------------------------------------------------------------------------------
IDENT_20 = "014ACMECORPSENS01100"  # no optional field
IDENT_33 = "113ACMECORPSENS011.0SN-1234567890"  # 13-character optional field


def test_parse_ident_fields() -> None:
    ident = parse_ident(IDENT_33, expected_address="1")
    assert ident.ok and ident.violations == []
    assert (ident.address, ident.version, ident.vendor) == ("1", "13", "ACMECORP")
    assert (ident.model, ident.sensor_version, ident.optional) == ("SENS01", "1.0", "SN-1234567890")
    assert ident.version_number == 13
    assert parse_ident(IDENT_20).optional == ""
    assert parse_ident(IDENT_20).version_number == 14


@pytest.mark.parametrize("body", [IDENT_20[:-1], IDENT_33 + "X", "0", ""])
def test_parse_ident_length(body: str) -> None:
    ident = parse_ident(body)
    assert "R-4.4.2-01" in ids(ident.violations)
    assert not ident.ok


@pytest.mark.parametrize("version", ["1.", "x4", " 4", "٣٤"])
def test_parse_ident_version_digits(version: str) -> None:
    ident = parse_ident("0" + version + IDENT_20[3:])
    assert ids(ident.violations) == ["R-4.4.2-02"]
    assert ident.version_number is None


def test_parse_ident_address() -> None:
    assert ids(parse_ident(IDENT_20, expected_address="3").violations) == ["R-4.3-01"]


# -- atttn / atttnn / atttnnn ----------------------------------------------------------------
@pytest.mark.parametrize(
    ("body", "digits", "ttt", "count"),
    [("00101", 1, 10, 1), ("0000000", 3, 0, 0), ("101504", 2, 15, 4), ("0045012", 3, 45, 12)],
)
def test_measurement_reply_clean(body: str, digits: int, ttt: int, count: int) -> None:
    reply = parse_measurement_reply(body, digits)
    assert reply == MeasurementReply(body[0], ttt, count, [])
    assert reply.ok


@pytest.mark.parametrize(
    ("body", "digits", "requirement"),
    [
        ("0010", 1, "R-4.4.5-01"),
        ("001011", 1, "R-4.4.5-01"),
        ("0a101", 1, "R-4.4.5-01"),
        ("00101", 2, "R-4.4.7-01"),
        ("0010100", 2, "R-4.4.7-01"),
        ("001 01", 2, "R-4.4.7-01"),
        ("000504", 3, "R-5.1-01"),
        ("00050040", 3, "R-5.1-01"),
        ("0", 1, "R-4.4.5-01"),
    ],
)
def test_measurement_reply_format(body: str, digits: int, requirement: str) -> None:
    reply = parse_measurement_reply(body, digits)
    assert ids(reply.violations) == [requirement]
    assert not reply.ok


def test_measurement_reply_partial_fields() -> None:
    reply = parse_measurement_reply("0x1x1", 1)
    assert reply.ttt is None and reply.count == 1
    reply = parse_measurement_reply("0010", 1)
    assert reply.ttt == 10 and reply.count is None
    assert parse_measurement_reply("0٣٣٣1", 1).ttt is None  # non-ASCII digits are not digits


def test_measurement_reply_requirement_override_and_address() -> None:
    reply = parse_measurement_reply("100504", 3, requirement="R-5.2-01", expected_address="1")
    assert ids(reply.violations) == ["R-5.2-01"]
    assert ids(parse_measurement_reply("10051", 1, expected_address="0").violations) == ["R-4.3-01"]
    with pytest.raises(ValueError):
        parse_measurement_reply("00101", 4)


@pytest.mark.parametrize(
    ("command", "digits"),
    [
        (c.measure("0"), 1),
        (c.measure("0", 3, crc=True), 1),
        (c.verify("0"), 1),
        (c.concurrent("0"), 2),
        (c.concurrent("0", 9, crc=True), 2),
        (c.high_volume_ascii("0"), 3),
        (c.high_volume_binary("0"), 3),
        (c.identify_measurement(c.concurrent("8", 5)), 2),
        (c.identify_measurement(c.high_volume_binary("8")), 3),
    ],
)
def test_measurement_digits(command: c.Command, digits: int) -> None:
    assert measurement_digits(command) == digits


@pytest.mark.parametrize("command", [c.data("0", 0), c.continuous("0", 0), c.identify("0")])
def test_measurement_digits_rejects_non_measurements(command: c.Command) -> None:
    with pytest.raises(ValueError):
        measurement_digits(command)


def test_parse_measurement_reply_for() -> None:
    assert parse_measurement_reply_for("0045012", c.high_volume_ascii("0")).ok
    assert ids(parse_measurement_reply_for("00450", c.high_volume_ascii("0")).violations) == [
        "R-5.1-01"
    ]
    assert ids(parse_measurement_reply_for("10050", c.high_volume_binary("1")).violations) == [
        "R-5.2-01"
    ]
    assert ids(parse_measurement_reply_for("0000", c.concurrent("0")).violations) == ["R-4.4.7-01"]
    assert parse_measurement_reply_for("801099", c.parse_command("8IC5!")).count == 99


@pytest.mark.parametrize(
    ("command", "body", "requirement"),
    [
        (c.measure("0"), "00000", "R-4.4.5-02"),
        (c.measure("0", crc=True), "00000", "R-4.4.5-02"),
        (c.verify("0"), "00000", "R-4.4.5-02"),
        (c.identify_measurement(c.measure("0")), "00000", "R-4.4.5-02"),
        (c.concurrent("0"), "000000", "R-4.4.7-02"),
        (c.concurrent("0", crc=True), "000000", "R-4.4.7-02"),
    ],
)
def test_zero_count_where_a_measurement_is_due(
    command: c.Command, body: str, requirement: str
) -> None:
    reply = parse_measurement_reply_for(body, command)
    assert ids(check_measurement_count(reply, command)) == [requirement]


@pytest.mark.parametrize(
    ("command", "body"),
    [
        (c.measure("0", 1), "00000"),
        (c.measure("0", 9, crc=True), "00000"),
        (c.concurrent("0", 2), "000000"),
        (c.high_volume_ascii("0"), "0000000"),
        (c.high_volume_binary("0"), "0000000"),
        (c.measure("0"), "00001"),
        (c.concurrent("0"), "000099"),
    ],
)
def test_zero_count_allowed_by_decision_a1(command: c.Command, body: str) -> None:
    reply = parse_measurement_reply_for(body, command)
    assert check_measurement_count(reply, command, version="14") == []


def test_concurrent_count_above_20_warns_under_v13_only() -> None:
    reply = parse_measurement_reply("001021", 2)
    (warning,) = check_measurement_count(reply, c.concurrent("0"), version="13")
    assert warning.requirement == "R-4.4.7-03" and warning.warning
    assert check_measurement_count(reply, c.concurrent("0"), version="14") == []
    assert (
        check_measurement_count(parse_measurement_reply("001020", 2), c.concurrent("0"), "13") == []
    )
    assert check_measurement_count(parse_measurement_reply("00x", 2), c.concurrent("0")) == []


# -- D and R replies -------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("command", "limit"),
    [
        (c.measure("0"), 35),
        (c.measure("0", 4, crc=True), 35),
        (c.verify("0"), 35),
        (c.concurrent("0"), 75),
        (c.concurrent("0", 1, crc=True), 75),
        (c.high_volume_ascii("0"), 75),
        (c.continuous("0", 0), 75),
        (c.continuous("0", 9, crc=True), 75),
        (c.identify_measurement(c.measure("0")), 35),
    ],
)
def test_expected_value_limit(command: c.Command, limit: int) -> None:
    assert expected_value_limit(command) == limit


@pytest.mark.parametrize("command", [c.high_volume_binary("0"), c.data("0", 0), c.identify("0")])
def test_expected_value_limit_rejects(command: c.Command) -> None:
    with pytest.raises(ValueError):
        expected_value_limit(command)


def test_data_reply_clean() -> None:
    reply = parse_data_reply("0+3.14+2.718", crc_expected=False, limit=35, expected_address="0")
    assert reply.values == ["+3.14", "+2.718"] and reply.crc is None and reply.crc_ok is None
    assert reply.ok and reply.violations == [] and reply.values_text == "+3.14+2.718"


def test_data_reply_with_crc() -> None:
    reply = parse_data_reply(with_crc("0+3.14-1"), crc_expected=True, limit=35)
    assert reply.values == ["+3.14", "-1"] and reply.crc_ok and reply.violations == []


@pytest.mark.parametrize(("body", "crc"), [("0", False), ("0AP@", True)])
def test_empty_data_reply_is_legal(body: str, crc: bool) -> None:
    reply = parse_data_reply(body, crc_expected=crc, limit=35)
    assert reply.values == [] and reply.violations == []


def test_data_reply_missing_crc() -> None:
    reply = parse_data_reply("0+3.14", crc_expected=True, limit=35)
    assert ids(reply.violations) == ["R-4.4.12-02"]
    assert reply.crc is None and reply.values == ["+3.14"]


def test_data_reply_short_crc() -> None:
    reply = parse_data_reply("0+3.14Oq", crc_expected=True, limit=35)
    assert ids(reply.violations) == ["R-4.4.12-02"]
    assert reply.values == ["+3.14"] and reply.crc == "Oq"


def test_data_reply_wrong_crc() -> None:
    reply = parse_data_reply("0+3.14OqY", crc_expected=True, limit=35)
    assert ids(reply.violations) == ["R-4.4.12-05"]
    assert reply.crc == "OqY" and reply.crc_ok is False
    assert "OqZ" in reply.violations[0].message


def test_data_reply_impossible_crc_encoding() -> None:
    """An impossible encoding is the encoding rule's fault; no value is compared with it."""
    reply = parse_data_reply("0+3.14PqZ", crc_expected=True, limit=35)
    assert ids(reply.violations) == ["R-4.4.12-06"]
    assert reply.crc_ok is False


def test_data_reply_unrequested_crc() -> None:
    reply = parse_data_reply("0+3.14OqZ", crc_expected=False, limit=35)
    assert ids(reply.violations) == ["R-4.4.12-03"]
    assert reply.values == ["+3.14"] and reply.crc == "OqZ" and reply.crc_ok is True
    stray = parse_data_reply("0+3.14A", crc_expected=False, limit=35)
    assert ids(stray.violations) == ["R-4.4.12-03"] and stray.crc_ok is None


def test_data_reply_extra_crc_like_character_is_a_value_error() -> None:
    reply = parse_data_reply(with_crc("0+3.14A"), crc_expected=True, limit=35)
    assert reply.crc_ok
    assert ids(reply.violations) == ["R-4.4.8-02"]


@pytest.mark.parametrize(("limit", "requirement"), [(35, "R-4.4-05"), (75, "R-4.4-05")])
def test_data_reply_value_limit(limit: int, requirement: str) -> None:
    exact = ("+1234.5" * 11)[:limit]
    assert len(exact) == limit and exact[-1].isdigit()
    assert parse_data_reply("0" + exact, crc_expected=False, limit=limit).violations == []
    over = parse_data_reply(with_crc("0" + exact + "+1"), crc_expected=True, limit=limit)
    assert ids(over.violations) == [requirement]


def test_data_reply_limit_requirement_override() -> None:
    reply = parse_data_reply("0" + "+1" * 18, crc_expected=False, limit=35, limit_requirement="X")
    assert ids(reply.violations) == ["X"]


@pytest.mark.parametrize(
    ("body", "warning"),
    [("0+1.2.3", False), ("01.5", False), ("0+12345678", False), ("0+.5", True), ("0-0", True)],
)
def test_data_reply_value_grammar(body: str, warning: bool) -> None:
    reply = parse_data_reply(body, crc_expected=False, limit=35)
    assert set(ids(reply.violations)) == {"R-4.4.8-02"}
    assert reply.ok is warning


def test_data_reply_address() -> None:
    assert ids(
        parse_data_reply("1+1", crc_expected=False, limit=35, expected_address="0").violations
    ) == ["R-4.3-01"]


def test_parse_data_reply_for_high_volume_ascii() -> None:
    ha = c.high_volume_ascii("0")
    assert parse_data_reply_for(with_crc("0+1"), ha).ok
    assert ids(parse_data_reply_for("0+1", ha).violations) == ["R-5.1-03"]
    long = with_crc("0" + "+1" * 38)
    assert ids(parse_data_reply_for(long, ha).violations) == ["R-5.1-03"]


def test_parse_data_reply_for_continuous() -> None:
    assert parse_data_reply_for("0+3.14", c.continuous("0", 0)).ok
    assert parse_data_reply_for("0AP@", c.continuous("0", 0, crc=True)).ok
    assert ids(parse_data_reply_for("0", c.continuous("0", 0, crc=True)).violations) == [
        "R-4.4.12-02"
    ]
    long = "0" + "+1" * 38
    assert ids(parse_data_reply_for(long, c.continuous("0", 3)).violations) == ["R-4.4.8.1-01"]


def test_parse_data_reply_for_measurements() -> None:
    assert ids(parse_data_reply_for("0" + "+1" * 18, c.measure("0")).violations) == ["R-4.4-05"]
    assert parse_data_reply_for("0" + "+1" * 18, c.concurrent("0")).ok
    assert ids(parse_data_reply_for("0+1", c.concurrent("0", crc=True)).violations) == [
        "R-4.4.12-02"
    ]
    assert ids(parse_data_reply_for(with_crc("0+1"), c.verify("0")).violations) == ["R-4.4.12-03"]
    with pytest.raises(ValueError):
        parse_data_reply_for("0+1", c.high_volume_binary("0"))
    with pytest.raises(ValueError):
        parse_data_reply_for("0+1", c.identify("0"))


def _replies(*bodies: str) -> list:
    return [parse_data_reply(b, crc_expected=False, limit=75) for b in bodies]


def test_data_sequence_clean() -> None:
    assert check_data_sequence(_replies("0+1+2", "0+3"), 3, limit=4) == []
    assert check_data_sequence(_replies("0+1"), 1, limit=35) == []
    assert check_data_sequence([], 0, limit=35) == []


@pytest.mark.parametrize(("announced", "bodies"), [(3, ("0+1+2",)), (1, ("0+1", "0+2"))])
def test_data_sequence_count(announced: int, bodies: tuple[str, ...]) -> None:
    assert ids(check_data_sequence(_replies(*bodies), announced, limit=2)) == ["R-4.4.8-03"]


def test_data_sequence_split_value() -> None:
    found = check_data_sequence(_replies("0+1.2", "034+5"), 2, limit=35)
    # the halves '+1.2' and '34' are one value (+1.234): the cut is R-4.4.8.3-01's, and the
    # count holds (counting the tail as a value of its own FAILed R-4.4.8-03 for the cut:
    # split-value + values-over-35, seed 4065)
    assert ids(found) == ["R-4.4.8.3-01"] and not found[0].warning
    # a count that is off with the halves joined is still off
    assert ids(check_data_sequence(_replies("0+1.2", "034+5"), 3, limit=35)) == [
        "R-4.4.8-03",
        "R-4.4.8.3-01",
    ]


def test_data_sequence_unsigned_first_value_after_an_empty_reply_is_no_split() -> None:
    """R-4.4.8.3-01: an empty D0 cut no value, so D1's unsigned first value is R-4.4.8-02's
    missing sign alone (groups-start-at-d1 + value-missing-sign + values-over-75, seed 4096:
    'D1 starts with '22.15', the rest of a split value' FAILed)."""
    assert check_data_sequence(_replies("0", "022.15+1013.2+45.7"), 3, limit=35) == []
    # a value cut behind a reply that held values is still the cut
    assert ids(check_data_sequence(_replies("0", "0+1.2", "034"), 1, limit=35)) == ["R-4.4.8.3-01"]


def test_data_sequence_room_left_is_a_warning() -> None:
    found = check_data_sequence(_replies("0+3.14", "0+2.718", "0+1.414"), 3, limit=35)
    assert ids(found) == ["R-4.4.8.3-03", "R-4.4.8.3-03"]
    assert all(v.warning for v in found)
    assert check_data_sequence(_replies("0+3.14", "0+2.718"), 2, limit=10) == []
    assert ids(check_data_sequence(_replies("0+3.14", "0+2.718"), 2, limit=11)) == ["R-4.4.8.3-03"]


finite = st.floats(min_value=-9_999_999, max_value=9_999_999, allow_nan=False)


@given(st.lists(finite, min_size=1, max_size=30), st.booleans(), st.sampled_from([35, 75]))
def test_sensor_side_replies_parse_clean(xs: list[float], crc: bool, limit: int) -> None:
    """What a conforming sensor builds with format_value/pack_values/ascii_crc parses clean
    and gives back the same values."""
    texts = [format_value(x) for x in xs if abs(x) < 9_999_999]
    got: list[str] = []
    for group in pack_values(texts, limit):
        body = with_crc("0" + group) if crc else "0" + group
        reply = parse_data_reply(body, crc_expected=crc, limit=limit)
        assert reply.violations == []
        got += reply.values
    assert got == texts


@given(st.text(max_size=90), st.booleans())
def test_parsers_never_raise(body: str, crc: bool) -> None:
    parse_data_reply(body, crc_expected=crc, limit=35)
    parse_metadata_reply(body, crc_expected=crc)
    parse_ident(body)
    for digits in (1, 2, 3):
        parse_measurement_reply(body, digits)
    split_line(body, crc_positions=3 if crc else 0)


# -- metadata --------------------------------------------------------------------------------
def test_metadata_clean() -> None:
    reply = parse_metadata_reply("0,PR,mm,precipitation rate per day;", crc_expected=False)
    assert reply.fields == ["PR", "mm", "precipitation rate per day"]
    assert not reply.invalid_index and reply.crc is None and reply.violations == []


def test_metadata_with_crc() -> None:
    reply = parse_metadata_reply(with_crc("0,TA,degC;"), crc_expected=True)
    assert reply.ok and reply.crc_ok and reply.fields == ["TA", "degC"]


@pytest.mark.parametrize(("body", "crc"), [("0", False), ("0AP@", True)])
def test_metadata_invalid_index_reply(body: str, crc: bool) -> None:
    reply = parse_metadata_reply(body, crc_expected=crc)
    assert reply.invalid_index and reply.fields == [] and reply.violations == []


def test_metadata_invalid_index_crc_mismatch() -> None:
    assert "R-6.2-02" in ids(parse_metadata_reply("0AP", crc_expected=True).violations)
    reply = parse_metadata_reply("0APA", crc_expected=True)
    assert reply.invalid_index and ids(reply.violations) == ["R-4.4.12-05"]


def test_metadata_invalid_index_without_due_crc() -> None:
    reply = parse_metadata_reply("0", crc_expected=True)
    assert reply.invalid_index and ids(reply.violations) == ["R-6.2-05"]


def test_metadata_invalid_index_with_unasked_crc() -> None:
    reply = parse_metadata_reply("0AP@", crc_expected=False)
    assert reply.invalid_index and ids(reply.violations) == ["R-6.2-05"]


@pytest.mark.parametrize(
    ("body", "crc", "requirement"),
    [
        ("0PR,mm;", False, "R-6.2-02"),
        ("0,PR,mm", False, "R-6.2-02"),
        ("0,,mm;", False, "R-6.2-02"),
        ("0,PR,mm;", True, "R-6.2-02"),  # CRC due but absent
        ("0,PR,m;m;", False, "R-6.2-03"),
        ("0,PR,m\x01m;", False, "R-6.2-03"),
        ("0,PR;", False, "R-6.2.2-01"),
        ("0,PR,mm;OOO", True, "R-4.4.12-05"),
        ("0,PR,mm;PPP", True, "R-4.4.12-06"),
    ],
)
def test_metadata_rejections(body: str, crc: bool, requirement: str) -> None:
    reply = parse_metadata_reply(body, crc_expected=crc)
    assert requirement in hard(reply.violations)
    assert not reply.ok


def test_metadata_length_counts_address_through_semicolon() -> None:
    """Decision A7: 75 characters from the address through ';', the CRC not counted."""
    body = "0,PR,mm," + "x" * 66 + ";"
    assert len(body) == 75
    assert parse_metadata_reply(body, crc_expected=False).violations == []
    assert parse_metadata_reply(with_crc(body), crc_expected=True).violations == []
    longer = "0,PR,mm," + "x" * 67 + ";"
    assert ids(parse_metadata_reply(longer, crc_expected=False).violations) == ["R-6.2-04"]


def test_metadata_empty_units_field_is_a_warning() -> None:
    reply = parse_metadata_reply("0,RH,;", crc_expected=False)
    assert ids(reply.violations) == ["R-6.2.2-01"] and reply.violations[0].warning and reply.ok
    assert parse_metadata_reply("0,RH, ;", crc_expected=False).violations == []


def test_metadata_address() -> None:
    reply = parse_metadata_reply("1,PR,mm;", crc_expected=False, expected_address="0")
    assert ids(reply.violations) == ["R-4.3-01"]


def test_an_unasked_metadata_crc_is_one_violation_not_two():
    """Issue 10: a CRC on a plain metadata reply is R-6.2-02 once, not also a ';' in a field."""
    body = "0,TA,degC;"
    reply = parse_metadata_reply(body + ascii_crc(body), crc_expected=False)
    assert [v.requirement for v in reply.violations] == ["R-6.2-02"]
    assert reply.fields == ["TA", "degC"]


def test_holds_values_is_a_digit_after_the_address():
    from conformance.protocol.crc import ascii_crc
    from conformance.protocol.responses import holds_values

    assert holds_values("0+1.5-2\r\n") and holds_values("01.5\r\n")  # a value without its sign
    assert holds_values(f"0+3{ascii_crc('0+3')}\r\n")
    assert not holds_values("0\r\n") and not holds_values(f"0{ascii_crc('0')}\r\n")
    assert not holds_values("0UNKN\r\n") and not holds_values("")
