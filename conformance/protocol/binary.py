"""High-volume binary packets (``aDBn!`` replies, SDI-12 v1.4 section 5.2).

A packet is ``address | size (uint16 LE) | type (uint8) | payload | CRC-16 (LE)``, sent 8N1
with no CR LF (R-4.1-03, R-5.2-02). The size field is the only framing, so a reader needs
:func:`packet_length` to know when a packet is complete. :func:`parse_binary_packet` never
raises: a truncated or malformed packet is evidence, returned with violations.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from enum import IntEnum

from conformance.protocol.commands import ADDRESS_CHARS
from conformance.protocol.crc import binary_crc
from conformance.protocol.values import Checked, Violation
from conformance.transcript import escape

HEADER_LEN = 4  # address, size low, size high, type
CRC_LEN = 2
EMPTY_LEN = HEADER_LEN + CRC_LEN  # R-5.2-06: the 6-byte empty packet
MAX_PAYLOAD = 1000  # R-5.2-04


class DataType(IntEnum):
    """Payload type codes of Table 16 (R-5.2.1-01); every multi-byte type is little-endian."""

    INVALID = 0
    INT8 = 1
    UINT8 = 2
    INT16 = 3
    UINT16 = 4
    INT32 = 5
    UINT32 = 6
    INT64 = 7
    UINT64 = 8
    FLOAT32 = 9
    FLOAT64 = 10


_FORMATS = {
    DataType.INT8: "b",
    DataType.UINT8: "B",
    DataType.INT16: "h",
    DataType.UINT16: "H",
    DataType.INT32: "i",
    DataType.UINT32: "I",
    DataType.INT64: "q",
    DataType.UINT64: "Q",
    DataType.FLOAT32: "f",
    DataType.FLOAT64: "d",
}


def type_size(dtype: DataType | int) -> int:
    """Bytes per value of ``dtype``; 0 for INVALID, which carries no data."""
    dtype = DataType(dtype)
    return struct.calcsize("<" + _FORMATS[dtype]) if dtype in _FORMATS else 0


def encode_values(dtype: DataType, values: list[int | float]) -> bytes:
    """The little-endian payload for ``values``; ValueError if one does not fit the type."""
    if dtype is DataType.INVALID:
        if values:
            raise ValueError("type 0 (invalid request) carries no values")
        return b""
    try:
        return struct.pack(f"<{len(values)}{_FORMATS[dtype]}", *values)
    except struct.error as exc:
        raise ValueError(f"values do not fit {dtype.name}: {exc}") from None


def decode_values(dtype: DataType, payload: bytes) -> list[int | float]:
    """Values of a payload whose length is a whole multiple of the type size."""
    if dtype is DataType.INVALID:
        return []
    fmt = _FORMATS[dtype]
    count = len(payload) // struct.calcsize("<" + fmt)
    return list(struct.unpack(f"<{count}{fmt}", payload))


def build_packet(address: str, dtype: DataType, values: list[int | float]) -> bytes:
    """A complete, correct packet, as a conforming sensor sends it (R-5.2-02/-03).

    ValueError for anything a conforming sensor could not send: a bad address, a value out of
    the type's range, more than 1000 payload bytes, or no values under a non-zero type.
    """
    if len(address) != 1 or address not in ADDRESS_CHARS:
        raise ValueError(f"bad address {address!r}")
    if not values and dtype is not DataType.INVALID:
        raise ValueError("a packet without values must be the type-0 empty packet (R-5.2-06)")
    payload = encode_values(DataType(dtype), values)
    if len(payload) > MAX_PAYLOAD:
        raise ValueError(f"payload of {len(payload)} bytes exceeds {MAX_PAYLOAD}")
    head = address.encode("ascii") + len(payload).to_bytes(2, "little") + bytes([dtype])
    return head + payload + binary_crc(head + payload)


def empty_packet(address: str) -> bytes:
    """The 6-byte packet for an index beyond the data (R-5.2-06): size 0, type 0."""
    return build_packet(address, DataType.INVALID, [])


def packet_length(prefix: bytes) -> int | None:
    """Total length of the packet that starts with ``prefix`` once its size field (bytes 1-2)
    has arrived; None before that. Lets a reader stop exactly at the packet's end."""
    if len(prefix) < 3:
        return None
    return EMPTY_LEN + int.from_bytes(prefix[1:3], "little")


@dataclass(frozen=True)
class BinaryPacket(Checked):
    """A parsed packet. ``dtype`` is the raw code when it is not a valid :class:`DataType`;
    ``payload`` is the bytes between header and CRC as received; ``values`` is empty unless
    the packet is framed by its size field and its payload fits the type."""

    address: str
    size: int
    dtype: DataType | int
    payload: bytes
    crc_ok: bool
    values: list[int | float]
    violations: list[Violation] = field(default_factory=list)

    @property
    def payload_known(self) -> bool:
        """The payload's length is on the wire: the size field agrees with the packet's
        length, or the CRC checks over the packet as read (so it ended where it was read to
        end, whatever its size field says). Else neither tells how long the payload was."""
        return len(self.payload) == self.size or self.crc_ok

    @property
    def is_empty(self) -> bool:
        """The R-5.2-06 empty packet: no payload and type 0."""
        return self.size == 0 and self.dtype == DataType.INVALID


def parse_binary_packet(data: bytes, expected_address: str | None = None) -> BinaryPacket:
    """Parse one ``aDBn!`` reply and check R-4.1-03, R-5.2-02..06 and R-5.2.1-01."""
    found: list[Violation] = []
    shown = escape(data[:16]) + ("..." if len(data) > 16 else "")
    if len(data) < EMPTY_LEN:
        found.append(Violation("R-5.2-02", f"packet '{shown}' has {len(data)} bytes, fewer than 6"))
    address = chr(data[0] & 0x7F) if data else ""
    if data and data[0] & 0x80:
        found.append(
            Violation(
                "R-4.1-03",
                f"address byte 0x{data[0]:02X} has bit 7 set (a parity bit where 8N1 is due)",
            )
        )
    if data and address not in ADDRESS_CHARS:
        found.append(Violation("R-4.3-04", f"packet starts with '{escape(address)}'"))
    elif expected_address is not None and data and address != expected_address:
        found.append(
            Violation("R-4.3-01", f"packet address '{address}', expected '{expected_address}'")
        )
    size = int.from_bytes(data[1:3], "little") if len(data) >= 3 else 0
    code = data[3] if len(data) >= HEADER_LEN else 0
    dtype: DataType | int = DataType(code) if code <= DataType.FLOAT64 else code
    framed = len(data) == EMPTY_LEN + size
    # Keep what actually sits between header and CRC as evidence, whatever the size field says.
    payload = data[HEADER_LEN : max(HEADER_LEN, len(data) - CRC_LEN)]
    if len(data) >= EMPTY_LEN and not framed:
        found.append(
            Violation(
                "R-5.2-02",
                f"packet is {len(data)} bytes but its size field {size} implies {EMPTY_LEN + size}",
            )
        )
    crc_ok = len(data) >= EMPTY_LEN and binary_crc(data[:-CRC_LEN]) == data[-CRC_LEN:]
    if len(data) >= EMPTY_LEN and not crc_ok:
        found.append(
            Violation(
                "R-5.2-03",
                f"CRC bytes {data[-2:].hex(' ')} do not match "
                f"{binary_crc(data[:-CRC_LEN]).hex(' ')} computed over the packet",
            )
        )
    if (framed and size > MAX_PAYLOAD) or len(payload) > MAX_PAYLOAD:
        # an unframed packet's size field is not evidence of its payload (R-5.2-02 says so)
        shown_size = size if framed else len(payload)
        found.append(
            Violation("R-5.2-04", f"payload size {shown_size} exceeds {MAX_PAYLOAD} bytes")
        )
    values: list[int | float] = []
    if not isinstance(dtype, DataType):
        found.append(Violation("R-5.2.1-01", f"data type code {code} is not defined (0-10)"))
    elif dtype is DataType.INVALID:
        if size:
            found.append(Violation("R-5.2.1-01", f"type 0 (no data) with a {size}-byte payload"))
    elif size == 0:
        found.append(Violation("R-5.2-06", f"empty packet has type {code}, not 0"))
    elif framed and size % type_size(dtype):
        # an unframed packet's size field is not evidence of its payload (R-5.2-02 says so),
        # nor are bytes that may have lost or gained one: a BE size field of 1002 read as
        # 59907 FAILed R-5.2-05 beside binary-size-big-endian (ninth round)
        found.append(
            Violation(
                "R-5.2-05",
                f"payload of {size} bytes is not a whole number of {dtype.name} values",
            )
        )
    elif not framed and crc_ok and len(payload) % type_size(dtype):
        # (seed 4216) a size field that disagrees with a packet whose CRC checks is no
        # evidence of its payload, but the bytes between header and CRC are: 9 bytes of
        # INT16 behind a big-endian size field (read as 2304, even) PASSed R-5.2-05
        found.append(
            Violation(
                "R-5.2-05",
                f"payload of {len(payload)} bytes between header and CRC (the CRC checks; the"
                f" size field says {size}) is not a whole number of {dtype.name} values",
            )
        )
    elif framed:
        values = decode_values(dtype, payload)
    return BinaryPacket(address, size, dtype, bytes(payload), crc_ok, values, found)
