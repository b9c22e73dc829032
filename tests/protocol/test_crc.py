"""CRC-16 vectors of requirements.md section 3 (R-4.4.12-05, R-4.4.12-06, R-5.2-03)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol.crc import (
    ascii_crc,
    binary_crc,
    crc16,
    encode_ascii,
    encode_binary,
    is_crc_char,
)

ASCII_VECTORS = [
    ("0+3.14+2.718+1.414", "Ipz", 0x9C3A),
    ("0+1.11+2.22+3.33+4.44+5.55+6.66", "I]q", 0x9771),
    ("0+7.77+8.88+9.99", "IvW", 0x9D97),
    ("0+3.14+2.718", "IWO", 0x95CF),
    ("0+3.14", "OqZ", 0xFC5A),
    ("0+2.718", "Gbc", 0x78A3),
    ("0+1.414", "GtW", 0x7D17),
    ("1+1.23+2.34+345+4.4678", "KoO", 0xBBCF),
    ("0+1.234-4.56+12354-0.00045+2.223+145.5+7.7003+4328.8+9+10+11.433+12", "Ba]", 0x285D),
    ("0", "AP@", 0x1400),
    ("0,CU,degrees C,average air temperature,calibration data,40,1235;", "@|e", 0x0F25),
]

BINARY_VECTORS = [
    ("31 04 00 03 FF FF 01 00", "C2 AC", 0xACC2),
    ("31 08 00 09 C3 F5 48 40 00 00 80 3F", "3B 6E", 0x6E3B),
    ("31 00 00 00", "0E FC", 0xFC0E),
]


def test_check_value_of_crc16_arc() -> None:
    assert crc16(b"123456789") == 0xBB3D
    assert crc16("123456789") == 0xBB3D


def test_empty_input_gives_initial_value_zero() -> None:
    assert crc16(b"") == 0


@pytest.mark.parametrize(("text", "chars", "value"), ASCII_VECTORS)
def test_ascii_vectors(text: str, chars: str, value: int) -> None:
    assert crc16(text) == value
    assert encode_ascii(value) == chars
    assert ascii_crc(text) == chars


def test_typo_of_2000_text_does_not_give_the_printed_crc() -> None:
    """v1.3 (2000) example f prints +1.1234 with Ba]; only the corrected +1.234 gives Ba]."""
    typo = "0+1.1234-4.56+12354-0.00045+2.223+145.5+7.7003+4328.8+9+10+11.433+12"
    assert crc16(typo) == 0xBCB9
    assert ascii_crc(typo) == "Kry"
    assert ascii_crc(typo) != "Ba]"
    assert ascii_crc(typo.replace("+1.1234", "+1.234", 1)) == "Ba]"


@pytest.mark.parametrize(("packet", "crc_hex", "value"), BINARY_VECTORS)
def test_binary_vectors(packet: str, crc_hex: str, value: int) -> None:
    data = bytes.fromhex(packet)
    assert crc16(data) == value
    assert binary_crc(data) == bytes.fromhex(crc_hex)
    assert encode_binary(value) == bytes.fromhex(crc_hex)


def test_binary_crc_is_low_byte_first() -> None:
    assert encode_binary(0x1234) == b"\x34\x12"


def test_ascii_encoding_bit_layout() -> None:
    """R-4.4.12-06: top 4 bits, middle 6 bits, low 6 bits, each ORed with 0x40."""
    assert encode_ascii(0x0000) == "@@@"
    assert encode_ascii(0xFFFF) == "O\x7f\x7f"
    assert encode_ascii(0xF000) == "O@@"
    assert encode_ascii(0x0FC0) == "@\x7f@"
    assert encode_ascii(0x003F) == "@@\x7f"


@given(st.integers(min_value=0, max_value=0xFFFF))
def test_ascii_encoding_is_reversible_and_in_crc_range(value: int) -> None:
    chars = encode_ascii(value)
    assert all(is_crc_char(c) for c in chars)
    assert 0x40 <= ord(chars[0]) <= 0x4F
    decoded = ((ord(chars[0]) & 0x0F) << 12) | ((ord(chars[1]) & 0x3F) << 6)
    decoded |= ord(chars[2]) & 0x3F
    assert decoded == value


@given(st.binary(max_size=64))
def test_appending_the_crc_le_gives_residue_zero(data: bytes) -> None:
    """A property of CRC-16/ARC: the CRC of data + its own LE CRC is 0. Catches a wrong
    polynomial, init or reflection that a handful of vectors could miss."""
    assert crc16(data + binary_crc(data)) == 0


def test_is_crc_char() -> None:
    assert is_crc_char("@") and is_crc_char("\x7f") and is_crc_char("z")
    for c in "+-.0123456789?\x80":
        assert not is_crc_char(c)
    assert not is_crc_char("") and not is_crc_char("AB")


def test_a_crc_asked_again_is_the_one_computed() -> None:
    """ascii_crc's memo gives what the CRC gives, the first time and after, across clears."""
    import random

    from conformance.protocol import crc

    rng = random.Random(9)
    texts = ["".join(rng.choice("0123456789+-.abcXYZ") for _ in range(rng.randrange(40)))
             for _ in range(300)]  # fmt: skip
    crc._ASCII_CRCS.clear()
    saved, crc._ASCII_CRCS_MAX = crc._ASCII_CRCS_MAX, 50
    try:
        for _round in range(3):
            for text in texts:
                assert crc.ascii_crc(text) == crc.encode_ascii(crc.crc16(text))
                assert len(crc._ASCII_CRCS) <= 50
    finally:
        crc._ASCII_CRCS_MAX = saved
