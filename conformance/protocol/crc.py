"""SDI-12 CRC-16 (R-4.4.12-05): CRC-16/ARC, reflected polynomial 0xA001, init 0, no final XOR.

Two encodings exist: three printable characters for ASCII replies (R-4.4.12-06) and two raw
bytes, low byte first, for high-volume binary packets (R-5.2-03).
"""

from __future__ import annotations

import re

ASCII_CRC_LEN = 3  # R-4.4.12-06: three characters after the last value


def _table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
        table.append(crc)
    return tuple(table)


_TABLE = _table()


def crc16(data: bytes | str) -> int:
    """CRC-16/ARC of ``data`` (text is taken as ASCII)."""
    if isinstance(data, str):
        data = data.encode("ascii", "surrogateescape")
    crc = 0
    for byte in data:
        crc = (crc >> 8) ^ _TABLE[(crc ^ byte) & 0xFF]
    return crc


def encode_ascii(crc: int) -> str:
    """The three CRC characters of R-4.4.12-06 (each 0x40..0x7F)."""
    return "".join(chr(0x40 | ((crc >> shift) & 0x3F)) for shift in (12, 6, 0))


#: ascii_crc of each text asked: the emulator's replies, the recorder's checks and the view
#: ask it of the same few hundred texts thousands of times a run (a faulty one more often:
#: every retry); cleared when it grows
_ASCII_CRCS: dict[str, str] = {}
_ASCII_CRCS_MAX = 4096


def ascii_crc(text: str) -> str:
    """The three CRC characters for ``text`` (address through the last value, no CR LF)."""
    found = _ASCII_CRCS.get(text)
    if found is None:
        found = encode_ascii(crc16(text))
        if len(_ASCII_CRCS) >= _ASCII_CRCS_MAX:
            _ASCII_CRCS.clear()
        _ASCII_CRCS[text] = found
    return found


def encode_binary(crc: int) -> bytes:
    """The two CRC bytes of a high-volume binary packet, low byte first (R-5.2-03)."""
    return bytes((crc & 0xFF, crc >> 8))


def binary_crc(packet: bytes) -> bytes:
    """The two CRC bytes for a binary packet's address, size, type and payload."""
    return encode_binary(crc16(packet))


#: the range of an ASCII CRC's characters: 0x40..0x7F; no value character (``+-.0-9``) is
#: in it
CRC_CHAR_FIRST, CRC_CHAR_LAST = 0x40, 0x7F
#: one character of that range, for searching a whole text in C (a D reply without a CRC
#: checked for stray CRC characters) rather than asking :func:`is_crc_char` of each
CRC_CHAR = re.compile(f"[{chr(CRC_CHAR_FIRST)}-{chr(CRC_CHAR_LAST)}]")


def is_crc_char(char: str) -> bool:
    """Whether ``char`` is one character of an ASCII CRC's range (:data:`CRC_CHAR_FIRST`..
    :data:`CRC_CHAR_LAST`)."""
    return len(char) == 1 and CRC_CHAR_FIRST <= ord(char) <= CRC_CHAR_LAST
