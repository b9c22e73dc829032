"""High-volume binary packets (R-4.1-03, R-5.2-02..06, R-5.2.1-01)."""

from __future__ import annotations

import math
import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol.binary import (
    BinaryPacket,
    DataType,
    build_packet,
    decode_values,
    empty_packet,
    encode_values,
    packet_length,
    parse_binary_packet,
    type_size,
)
from conformance.protocol.crc import binary_crc
from conformance.protocol.values import Violation


def ids(violations: list[Violation]) -> list[str]:
    return [v.requirement for v in violations]


def with_crc(head_and_payload: bytes) -> bytes:
    return head_and_payload + binary_crc(head_and_payload)


SIZES = {0: 0, 1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 8, 8: 8, 9: 4, 10: 8}


@pytest.mark.parametrize(("code", "size"), SIZES.items())
def test_type_codes_and_sizes(code: int, size: int) -> None:
    assert type_size(DataType(code)) == size
    assert type_size(code) == size


def test_type_size_rejects_undefined_codes() -> None:
    with pytest.raises(ValueError):
        type_size(11)


def test_table_18_packets_are_built_exactly() -> None:
    """The three packets of the 5.2.2 example, byte for byte."""
    assert build_packet("1", DataType.INT16, [-1, 1]) == bytes.fromhex(
        "31 04 00 03 FF FF 01 00 C2 AC"
    )
    assert build_packet("1", DataType.FLOAT32, [3.14, 1.0]) == bytes.fromhex(
        "31 08 00 09 C3 F5 48 40 00 00 80 3F 3B 6E"
    )
    assert empty_packet("1") == bytes.fromhex("31 00 00 00 0E FC")


def test_build_packet_rejections() -> None:
    with pytest.raises(ValueError):
        build_packet("#", DataType.UINT8, [1])
    with pytest.raises(ValueError):
        build_packet("10", DataType.UINT8, [1])
    with pytest.raises(ValueError):
        build_packet("0", DataType.UINT8, [256])
    with pytest.raises(ValueError):
        build_packet("0", DataType.INT8, [-129])
    with pytest.raises(ValueError):
        build_packet("0", DataType.INVALID, [1])
    with pytest.raises(ValueError):
        build_packet("0", DataType.INT16, [])  # size 0 must be the type-0 empty packet
    with pytest.raises(ValueError):
        build_packet("0", DataType.UINT8, [0] * 1001)  # R-5.2-04
    largest = build_packet("0", DataType.UINT8, [0] * 1000)
    assert len(largest) == 1006 and parse_binary_packet(largest).violations == []
    assert len(build_packet("0", DataType.FLOAT64, [0.0] * 125)) == 1006


def test_encode_decode_values() -> None:
    assert encode_values(DataType.UINT16, [0x1234]) == b"\x34\x12"
    assert decode_values(DataType.INT32, b"\xff\xff\xff\xff") == [-1]
    assert encode_values(DataType.INVALID, []) == b""
    assert decode_values(DataType.INVALID, b"") == []


def test_packet_length() -> None:
    assert packet_length(b"") is None
    assert packet_length(b"1") is None
    assert packet_length(b"1\x04") is None
    assert packet_length(b"1\x04\x00") == 10
    assert packet_length(bytes.fromhex("31 e8 03 02")) == 1006
    assert packet_length(empty_packet("1")) == 6


def test_parse_empty_packet() -> None:
    packet = parse_binary_packet(empty_packet("1"), expected_address="1")
    assert packet == BinaryPacket("1", 0, DataType.INVALID, b"", True, [], [])
    assert packet.is_empty and packet.ok


def test_parse_table_18() -> None:
    first = parse_binary_packet(bytes.fromhex("31 04 00 03 FF FF 01 00 C2 AC"))
    assert first.ok and first.dtype is DataType.INT16 and first.values == [-1, 1]
    second = parse_binary_packet(bytes.fromhex("31 08 00 09 C3 F5 48 40 00 00 80 3F 3B 6E"))
    assert second.ok and second.dtype is DataType.FLOAT32
    assert second.values == [pytest.approx(3.14, rel=1e-7), 1.0]
    assert not second.is_empty


def test_truncated_packets() -> None:
    for cut in range(6):
        packet = parse_binary_packet(empty_packet("1")[:cut])
        assert "R-5.2-02" in ids(packet.violations)
        assert not packet.crc_ok and not packet.ok


def test_size_field_disagrees_with_length() -> None:
    full = build_packet("1", DataType.INT16, [-1, 1])
    short = with_crc(full[:-3])  # one payload byte missing, CRC recomputed
    packet = parse_binary_packet(short)
    # the CRC checks over the packet as read: its 3 payload bytes are no whole INT16 values
    assert ids(packet.violations) == ["R-5.2-02", "R-5.2-05"]
    assert packet.values == [] and packet.payload == b"\xff\xff\x01"
    long = with_crc(full[:-2] + b"\x00")  # a trailing extra byte
    packet = parse_binary_packet(long)
    assert ids(packet.violations) == ["R-5.2-02", "R-5.2-05"]
    assert packet.values == [] and packet.payload == b"\xff\xff\x01\x00\x00"


def test_an_unframed_packet_s_size_field_is_no_evidence_of_its_values() -> None:
    """A size field sent high byte first (1002 read as 59907, odd) says nothing of whether
    the payload holds whole UINT16 values: R-5.2-02 only (R-5.2-04 still sees the 1002
    bytes that came)."""
    payload = struct.pack("<501H", *range(501))
    packet = with_crc(b"1" + (1002).to_bytes(2, "big") + bytes([DataType.UINT16]) + payload)
    assert ids(parse_binary_packet(packet).violations) == ["R-5.2-02", "R-5.2-04"]


def test_bad_crc() -> None:
    data = bytearray(build_packet("1", DataType.UINT8, [1, 2, 3]))
    data[-1] ^= 0xFF
    packet = parse_binary_packet(bytes(data))
    assert ids(packet.violations) == ["R-5.2-03"] and not packet.crc_ok
    assert packet.values == [1, 2, 3]  # the payload is still shown as evidence


def test_crc_sent_high_byte_first_is_wrong() -> None:
    data = build_packet("1", DataType.INT16, [-1, 1])
    swapped = data[:-2] + data[-1:] + data[-2:-1]
    assert ids(parse_binary_packet(swapped).violations) == ["R-5.2-03"]


def test_payload_over_1000_bytes() -> None:
    head = b"1" + (1002).to_bytes(2, "little") + bytes([DataType.INT16])
    packet = parse_binary_packet(with_crc(head + bytes(1002)))
    assert ids(packet.violations) == ["R-5.2-04"]


@pytest.mark.parametrize("code", [11, 12, 0x7F, 0xFF])
def test_undefined_type_codes(code: int) -> None:
    packet = parse_binary_packet(with_crc(b"1\x02\x00" + bytes([code]) + b"\x01\x02"))
    assert ids(packet.violations) == ["R-5.2.1-01"]
    assert packet.dtype == code and not isinstance(packet.dtype, DataType)


def test_type_zero_with_payload() -> None:
    packet = parse_binary_packet(with_crc(b"1\x02\x00\x00\x01\x02"))
    assert ids(packet.violations) == ["R-5.2.1-01"] and not packet.is_empty


def test_empty_packet_with_nonzero_type() -> None:
    packet = parse_binary_packet(with_crc(b"1\x00\x00\x03"))
    assert ids(packet.violations) == ["R-5.2-06"] and not packet.is_empty


@pytest.mark.parametrize(("dtype", "size"), [(DataType.INT16, 3), (DataType.FLOAT32, 6)])
def test_payload_not_a_multiple_of_the_type(dtype: DataType, size: int) -> None:
    head = b"1" + size.to_bytes(2, "little") + bytes([dtype])
    packet = parse_binary_packet(with_crc(head + bytes(size)))
    assert ids(packet.violations) == ["R-5.2-05"] and packet.values == []


def test_address_sent_with_parity_bit() -> None:
    """'1' (0x31) has an odd number of ones, so 7E1 would set bit 7 (R-4.1-03: 8N1 due)."""
    data = with_crc(b"\xb1\x00\x00\x00")
    packet = parse_binary_packet(data)
    assert ids(packet.violations) == ["R-4.1-03"]
    assert packet.address == "1"


def test_address_checks() -> None:
    assert ids(parse_binary_packet(empty_packet("1"), expected_address="0").violations) == [
        "R-4.3-01"
    ]
    assert ids(parse_binary_packet(with_crc(b"#\x00\x00\x00")).violations) == ["R-4.3-04"]


# -- round trips ------------------------------------------------------------------------------
def _int_values(bits: int, signed: bool) -> st.SearchStrategy[int]:
    if signed:
        return st.integers(-(2 ** (bits - 1)), 2 ** (bits - 1) - 1)
    return st.integers(0, 2**bits - 1)


VALUE_STRATEGIES = {
    DataType.INT8: _int_values(8, True),
    DataType.UINT8: _int_values(8, False),
    DataType.INT16: _int_values(16, True),
    DataType.UINT16: _int_values(16, False),
    DataType.INT32: _int_values(32, True),
    DataType.UINT32: _int_values(32, False),
    DataType.INT64: _int_values(64, True),
    DataType.UINT64: _int_values(64, False),
    DataType.FLOAT32: st.floats(width=32, allow_nan=False),
    DataType.FLOAT64: st.floats(allow_nan=False),
}


def test_every_type_has_a_strategy() -> None:
    assert set(VALUE_STRATEGIES) | {DataType.INVALID} == set(DataType)


@st.composite
def typed_values(draw: st.DrawFn) -> tuple[DataType, list[int | float]]:
    dtype = draw(st.sampled_from(list(DataType)))
    if dtype is DataType.INVALID:
        return dtype, []
    count = draw(st.integers(1, 1000 // type_size(dtype)))
    values = draw(st.lists(VALUE_STRATEGIES[dtype], min_size=count, max_size=count))
    return dtype, values


@given(st.sampled_from("0123456789AZaz"), typed_values())
def test_build_then_parse_round_trips(address: str, typed: tuple[DataType, list]) -> None:
    dtype, values = typed
    data = build_packet(address, dtype, values)
    assert packet_length(data[:3]) == len(data)
    packet = parse_binary_packet(data, expected_address=address)
    assert packet.violations == [] and packet.crc_ok
    assert packet.address == address and packet.dtype is dtype
    assert packet.size == len(values) * type_size(dtype)
    assert packet.values == values


@given(st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=1, max_size=20))
def test_float64_nan_survives_bit_exactly(values: list[float]) -> None:
    packet = parse_binary_packet(build_packet("0", DataType.FLOAT64, values))
    assert packet.ok
    assert struct.pack(f"<{len(values)}d", *packet.values) == struct.pack(
        f"<{len(values)}d", *values
    )
    assert [math.isnan(v) for v in packet.values] == [math.isnan(v) for v in values]


@given(st.binary(max_size=40))
def test_parser_never_raises(data: bytes) -> None:
    packet = parse_binary_packet(data)
    if packet.ok:
        assert len(data) == packet_length(data)


def _big_endian_sized(payload: bytes, code: int = 3) -> bytes:
    """An INT16 packet whose size field is sent high byte first (binary-size-big-endian)."""
    return with_crc(b"0" + len(payload).to_bytes(2, "big") + bytes([code]) + payload)


def test_a_ragged_payload_behind_an_unreadable_size_field_is_judged_by_its_crc() -> None:
    """(seed 4216, binary-payload-not-multiple + binary-size-big-endian) 9 bytes of INT16
    behind a size field read as 2304 (even) PASSed R-5.2-05: the CRC checks over the packet
    as read, so the 9 bytes between header and CRC are its payload."""
    packet = parse_binary_packet(_big_endian_sized(bytes(9)), expected_address="0")
    assert packet.payload_known
    assert ids(packet.violations) == ["R-5.2-02", "R-5.2-05"]
    whole = parse_binary_packet(_big_endian_sized(bytes(8)), expected_address="0")
    assert ids(whole.violations) == ["R-5.2-02"]  # 8 bytes: whole INT16 values


def test_a_payload_neither_its_size_nor_its_crc_bounds_is_unknown() -> None:
    data = bytearray(_big_endian_sized(bytes(9)))
    data[-1] ^= 0x01  # the CRC no longer checks
    packet = parse_binary_packet(bytes(data), expected_address="0")
    assert not packet.payload_known
    assert "R-5.2-05" not in ids(packet.violations)
