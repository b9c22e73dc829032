"""Where an SDI-12 reply ends and what frames it (sections 4.2, 4.4.13.1, 5.2).

Three framings exist, and every reader of the bus (the tool's recorder deciding when to stop
receiving, the judges cutting a transcript into replies, the report drawing it) must agree on
them, so they are stated once, here:

- an ASCII reply ends with CR LF (R-4.2-03); everything before it is printable (R-4.2-02),
  except that CRC characters 2 and 3 may be 0x7F;
- multi-line text (decision A10) starts ``a<STX>``, ends each line with CR LF and the last
  one with ETX (R-4.4.13.1-01);
- a high-volume binary packet has no terminator: its size field says where it ends
  (:func:`conformance.protocol.binary.packet_length`, R-5.2-02).

A command ends with ``!``. Functions here take 7-bit character codes, not transcript events,
so the protocol layer stays free of I/O types.
"""

from __future__ import annotations

from collections.abc import Sequence

from conformance.protocol.crc import ASCII_CRC_LEN, is_crc_char

CR, LF = 0x0D, 0x0A
CRLF = "\r\n"  # R-4.2-03: every ASCII reply ends with it
STX, ETX = 0x02, 0x03  # multi-line text markers (4.4.13.1)
TEXT_END = CRLF + chr(ETX)  # the end of a complete multi-line text
COMMAND_END = "!"  # the last character of every command


def ends_line(codes: Sequence[int]) -> bool:
    """The characters so far (7-bit codes) end in CR LF."""
    return len(codes) >= 2 and codes[-2] == CR and codes[-1] == LF


def is_text(codes: Sequence[int]) -> bool:
    """A multi-line text reply: STX right after the address."""
    return len(codes) >= 2 and codes[1] == STX


def strip_crlf(text: str) -> str:
    """``text`` without its final CR LF, if it has one."""
    return text[:-2] if text.endswith(CRLF) else text


def crc_tail(body: str) -> bool:
    """``body`` (address first, no CR LF) ends in an ASCII CRC's worth of CRC characters after
    its address: the only way to tell a CRC is there when nobody knows whether one is due
    (value characters are never CRC characters)."""
    return len(body) > ASCII_CRC_LEN and all(is_crc_char(c) for c in body[-ASCII_CRC_LEN:])


def unprintable(body: str, crc_positions: int = 0) -> list[str]:
    """The characters of ``body`` that R-4.2-02 forbids, in order of appearance.

    ``crc_positions`` (3 where a CRC ends the body) exempts 0x7F in that many final
    characters: CRC characters 2 and 3 may legally be 0x7F.
    """
    if body.isascii() and body.isprintable():
        return []  # the usual body: nothing to list
    exempt_from = len(body) - crc_positions
    return [
        c
        for i, c in enumerate(body)
        if not 0x20 <= ord(c) <= 0x7E and not (c == "\x7f" and i >= exempt_from)
    ]
