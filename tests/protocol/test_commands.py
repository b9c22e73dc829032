"""The v1.4 command grammar: every form round-trips, every rejection path is exercised.

Requirements touched: R-4.2-01 (printable), R-4.3-01/-04 (address), R-4.4-04 (``!`` only at the
end), R-4.4.3-01/-02 (``?`` wildcard), R-5.1-02/R-5.1-04 (no leading zeros after D),
R-6.1-01 (no identify form for R), R-6.2-01 (metadata index is three digits).
"""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol import commands as c
from conformance.protocol.commands import ADDRESS_CHARS, Command, CommandError, Kind, parse_command


def _measurements(a: str) -> list[Command]:
    """Every measurement-starting command of v1.4 for address ``a``."""
    out = [c.verify(a), c.high_volume_ascii(a), c.high_volume_binary(a)]
    for crc in (False, True):
        for group in range(10):
            out += [c.measure(a, group, crc), c.concurrent(a, group, crc)]
    return out


def _all_v14_forms(a: str = "0") -> list[Command]:
    forms = [c.acknowledge(a), c.query_address(), c.identify(a), c.change_address(a, "5")]
    measurements = _measurements(a)
    continuous = [c.continuous(a, i, crc) for crc in (False, True) for i in range(10)]
    forms += measurements + continuous
    forms += [c.data(a, i) for i in (0, 1, 9, 10, 99, 100, 999)]
    forms += [c.binary_data(a, i) for i in (0, 1, 9, 10, 99, 100, 999)]
    forms += [c.identify_measurement(m) for m in measurements]
    forms += [c.metadata(t, p) for t in measurements + continuous for p in (1, 9, 99, 999)]
    forms += [c.metadata(c.measure(a), 0)]  # _000 is the probe for the invalid-index reply
    forms += [c.extended(a, "XLOG"), c.extended(a, "XA+1.5"), c.extended(a, "Z")]
    return forms


ALL_FORMS = _all_v14_forms()


@pytest.mark.parametrize("command", ALL_FORMS, ids=[x.text() for x in ALL_FORMS])
def test_every_v14_form_round_trips(command: Command) -> None:
    assert parse_command(command.text()) == command
    assert parse_command(command.encode()) == command


def test_every_form_has_distinct_text() -> None:
    texts = [x.text() for x in ALL_FORMS]
    assert len(texts) == len(set(texts))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("0!", Command("0", Kind.ACKNOWLEDGE)),
        ("?!", Command("?", Kind.QUERY_ADDRESS)),
        ("zI!", Command("z", Kind.IDENTIFY)),
        ("0AB!", Command("0", Kind.CHANGE_ADDRESS, new_address="B")),
        ("0M!", Command("0", Kind.MEASURE)),
        ("0MC7!", Command("0", Kind.MEASURE, crc=True, group=7)),
        ("1CC!", Command("1", Kind.CONCURRENT, crc=True)),
        ("0C5!", Command("0", Kind.CONCURRENT, group=5)),
        ("0V!", Command("0", Kind.VERIFY)),
        ("0R3!", Command("0", Kind.CONTINUOUS, group=3)),
        ("0RC0!", Command("0", Kind.CONTINUOUS, crc=True, group=0)),
        ("0HA!", Command("0", Kind.HIGH_VOLUME_ASCII)),
        ("1HB!", Command("1", Kind.HIGH_VOLUME_BINARY)),
        ("0D12!", Command("0", Kind.DATA, index=12)),
        ("1DB2!", Command("1", Kind.BINARY_DATA, index=2)),
        ("8IC5!", Command("8", Kind.IDENTIFY_MEASUREMENT, target=c.concurrent("8", 5))),
        ("0ICC_001!", Command("0", Kind.METADATA, target=c.concurrent("0", 0, True), param=1)),
        ("0IRC9_099!", Command("0", Kind.METADATA, target=c.continuous("0", 9, True), param=99)),
        ("0IHB_120!", Command("0", Kind.METADATA, target=c.high_volume_binary("0"), param=120)),
        ("0XRESET!", Command("0", Kind.EXTENDED, body="XRESET")),
    ],
)
def test_parse_fields(text: str, expected: Command) -> None:
    assert parse_command(text) == expected


def test_classification_properties() -> None:
    assert c.measure("0").starts_measurement and not c.measure("0").is_concurrent
    assert c.concurrent("0").is_concurrent and c.high_volume_binary("0").is_concurrent
    assert not c.data("0", 0).starts_measurement
    assert c.high_volume_ascii("0").returns_crc and c.high_volume_binary("0").returns_crc
    assert c.measure("0", crc=True).returns_crc and not c.measure("0").returns_crc
    assert c.continuous("0", 1, crc=True).returns_crc
    assert c.measure("0", 2).with_address("7").text() == "7M2!"
    assert str(c.metadata(c.verify("3"), 4)) == "3IV_004!"


def test_constructors_reject_forms_without_identify_or_metadata() -> None:
    with pytest.raises(ValueError):
        c.identify_measurement(c.continuous("0", 0))  # R-6.1-01: no identify form for R
    with pytest.raises(ValueError):
        c.metadata(c.data("0", 0), 1)


def test_wildcard_with_other_commands_only_when_allowed() -> None:
    """R-4.4.3-02: a sensor may accept ``?`` elsewhere; the default grammar does not."""
    with pytest.raises(CommandError, match="wildcard"):
        parse_command("?M!")
    assert parse_command("?M!", allow_wildcard=True) == c.measure("?")
    assert parse_command("?I!", allow_wildcard=True) == c.identify("?")


REJECTIONS = [
    # (text, fragment of the reason)
    ("", "empty"),
    ("0M", "does not end with '!'"),
    ("0M!!", "before the end"),
    ("0!M!", "before the end"),
    ("!", "no address"),
    ("#M!", "bad address"),
    (" M!", "bad address"),
    ("?M!", "wildcard"),
    ("?D0!", "wildcard"),
    ("0M\r!", "non-printable"),
    ("0\x00!", "non-printable"),
    ("0M\x7f!", "non-printable"),
    ("0Mé!", "non-printable"),
    ("0D01!", "leading zero"),
    ("0D00!", "leading zero"),
    ("0DB007!", "leading zero"),
    ("0M01!", "leading zero"),
    ("0MC01!", "leading zero"),
    ("0C05!", "leading zero"),
    ("0CC00!", "leading zero"),
    ("0R01!", "leading zero"),
    ("0RC05!", "leading zero"),
    ("0A!", "exactly one new address"),
    ("0A12!", "exactly one new address"),
    ("0A#!", "bad new address"),
    ("0A?!", "bad new address"),
    ("0M0!", "unknown command form"),
    ("0M10!", "unknown command form"),
    ("0MCC!", "unknown command form"),
    ("0MX!", "unknown command form"),
    ("0VC!", "unknown command form"),
    ("0H!", "unknown command form"),
    ("0HC!", "unknown command form"),
    ("0R!", "unknown command form"),
    ("0RC!", "unknown command form"),
    ("0R10!", "unknown command form"),
    ("0D!", "unknown command form"),
    ("0DB!", "unknown command form"),
    ("0D1000!", "unknown command form"),
    ("0DB1000!", "unknown command form"),
    ("0Dx!", "unknown command form"),
    ("0IX!", "unknown identify form"),
    ("0ID0!", "unknown identify form"),
    ("0I_001!", "unknown identify form"),
    ("0IR_001!", "unknown identify form"),
    ("0IR0!", "continuous commands have no identify form"),
    ("0IRC3!", "continuous commands have no identify form"),
    ("0IM_01!", "not three digits"),
    ("0IM_0001!", "not three digits"),
    ("0IM_!", "not three digits"),
    ("0IM_abc!", "not three digits"),
    ("0IHA_1e2!", "not three digits"),
]


@pytest.mark.parametrize(("text", "reason"), REJECTIONS)
def test_rejections(text: str, reason: str) -> None:
    with pytest.raises(CommandError) as info:
        parse_command(text)
    assert reason in info.value.reason
    assert info.value.text == text


def test_non_ascii_bytes_are_rejected() -> None:
    with pytest.raises(CommandError, match="non-ASCII"):
        parse_command(b"0M\xff!")


def test_command_error_is_a_value_error() -> None:
    with pytest.raises(ValueError):
        parse_command("0M")


# -- property tests --------------------------------------------------------------------------
addresses = st.sampled_from(ADDRESS_CHARS)
_measurement = st.one_of(
    st.builds(c.measure, addresses, st.integers(0, 9), st.booleans()),
    st.builds(c.concurrent, addresses, st.integers(0, 9), st.booleans()),
    st.builds(c.verify, addresses),
    st.builds(c.high_volume_ascii, addresses),
    st.builds(c.high_volume_binary, addresses),
)
_continuous = st.builds(c.continuous, addresses, st.integers(0, 9), st.booleans())
_extended_body = st.builds(
    lambda head, tail: head + tail,
    st.characters(min_codepoint=0x20, max_codepoint=0x7E, exclude_characters="!MVCDRIAH"),
    st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E, exclude_characters="!")),
)
valid_commands = st.one_of(
    st.builds(c.acknowledge, addresses),
    st.just(c.query_address()),
    st.builds(c.identify, addresses),
    st.builds(c.change_address, addresses, addresses),
    _measurement,
    _continuous,
    st.builds(c.data, addresses, st.integers(0, 999)),
    st.builds(c.binary_data, addresses, st.integers(0, 999)),
    st.builds(c.identify_measurement, _measurement),
    st.builds(c.metadata, st.one_of(_measurement, _continuous), st.integers(0, 999)),
    st.builds(c.extended, addresses, _extended_body),
)


@given(valid_commands)
def test_random_valid_commands_round_trip(command: Command) -> None:
    text = command.text()
    assert parse_command(text) == command
    assert parse_command(text).text() == text


@given(st.text(max_size=12))
def test_random_text_raises_only_command_error(text: str) -> None:
    try:
        command = parse_command(text)
    except CommandError:
        return
    assert command.text() == text  # whatever parses is canonical


@given(st.text(alphabet="0?!MCVDRIAHB_X123", max_size=10))
def test_command_alphabet_raises_only_command_error(text: str) -> None:
    """Text drawn from the command letters reaches the deep branches of the parser."""
    try:
        command = parse_command(text)
    except CommandError:
        return
    assert command.text() == text


@given(st.binary(max_size=12))
def test_random_bytes_raise_only_command_error(data: bytes) -> None:
    try:
        command = parse_command(data)
    except CommandError:
        return
    assert command.encode() == data


def _text_made(command: Command) -> str:
    """Command.text() worked out, as before matrix18 kept it on the command."""
    return f"{command.address}{command.code}!"


@pytest.mark.parametrize("command", ALL_FORMS, ids=[x.text() for x in ALL_FORMS])
def test_text_kept_is_the_text_made(command: Command) -> None:
    """Issue 22, matrix18: a command's text is made once and kept on it (frozen); asked
    again, after an address change (a new command), and after a pickle round trip, it is
    the text the command's fields make, and it leaves equality and hashing alone."""
    import pickle

    assert command.text() == _text_made(command)
    assert command.text() is command.text()  # kept
    moved = command.with_address("7")
    assert moved.text() == _text_made(moved) and moved.text().startswith("7")
    again = pickle.loads(pickle.dumps(command))
    assert again == command and hash(again) == hash(command)
    assert again.text() == _text_made(again)
    fresh = Command(**{f: getattr(command, f) for f in command.__dataclass_fields__})
    assert fresh == command and hash(fresh) == hash(command)
