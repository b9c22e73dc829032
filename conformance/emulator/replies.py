"""A reply under construction, and how it becomes wire frames.

The emulator first describes a reply (its kind, the text up to where a CRC would go, whether a
CRC follows, the terminator) and only then encodes it. Faults rewrite the description between
those two steps, so a fault that corrupts values still gets a CRC computed over the corrupted
text (the corruption is the only deviation), while a CRC fault can set the CRC text itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from ..protocol.commands import Command
from ..protocol.crc import ascii_crc, binary_crc
from ..protocol.framing import CRLF
from ..transcript import encode_7e1


class ReplyKind(StrEnum):
    ACKNOWLEDGE = "ack"  # a!
    ADDRESS = "address"  # ?!
    IDENTIFICATION = "ident"  # aI!
    CHANGE_ADDRESS = "change-address"  # aAb!
    START = "start"  # atttn / atttnn / atttnnn after a measurement command
    IDENTIFY = "identify"  # the same shape after an identify-measurement command
    SERVICE_REQUEST = "service-request"
    CHATTER = "chatter"  # only ever sent by a fault
    UNKNOWN = "unknown"  # a fault's text for what the sensor does not know (aUNKN)
    DATA = "data"  # aDn!
    CONTINUOUS = "continuous"  # aRn! / aRCn!
    METADATA = "metadata"  # aI<m>_nnn!
    EXTENDED = "extended"
    BINARY = "binary"  # aDBn! packet (8N1)


@dataclass
class BinaryParts:
    """A high-volume binary packet before encoding (R-5.2-02): fields kept apart for faults.

    A fault spoils the CRC as an edit of the packet's own CRC, made when encoding
    (``crc_flip`` xor'ed into its low byte, ``crc_swap`` sending it high byte first), so a
    CRC fault composes with one that changes the address, type or payload in either order."""

    address: int
    dtype: int
    payload: bytes
    crc_flip: int = 0
    crc_swap: bool = False  # the correct CRC goes low byte first (R-5.2-03)
    size_order: str = "little"  # the size field's byte order (R-5.2-02 says LSB first)

    def encode(self) -> bytes:
        order = "big" if self.size_order == "big" else "little"
        head = bytes([self.address]) + len(self.payload).to_bytes(2, order)
        head += bytes([self.dtype])
        low, high = binary_crc(head + self.payload)
        low ^= self.crc_flip
        if self.crc_swap and low == high:
            low ^= 0x01  # swapping equal bytes would change nothing: flip a bit so it shows
        crc = bytes((high, low) if self.crc_swap else (low, high))
        return head + self.payload + crc


@dataclass
class Reply:
    """One reply of the emulator.

        ``command`` is what it answers (None for service requests); ``source`` is the measurement
        command behind data, start and identify replies; ``digits`` the count width of start and
        identify replies (1, 2 or 3); ``repeat`` how often this D page was sent before (so a fault
        can make repeats differ). A fault spoils the CRC of a reply that carries one (``crc``) by
    ``crc_shift`` (added to the last character's six bits) or ``crc_high`` (the bits or'ed into
    each character instead of 0x40), both applied to the CRC of the final body when encoding:
    so the two compose in either order, a later rewrite of the body keeps the CRC spoiled (not
    stale), and a fault that drops the CRC drops a spoiled one too.
        ``flip_parity`` lists character positions sent with the wrong parity bit.
    """

    kind: ReplyKind
    body: str
    command: Command | None = None
    source: Command | None = None
    crc: bool = False
    crc_shift: int = 0
    crc_high: int = 0x40
    end: str = CRLF
    digits: int = 0
    repeat: int = 0
    binary: BinaryParts | None = None
    flip_parity: tuple[int, ...] = field(default=())

    @property
    def address(self) -> str:
        return self.body[:1]

    def text(self) -> str:
        """Everything sent, as text (ASCII replies only)."""
        crc = ""
        if self.crc:
            sixes = [ord(c) & 0x3F for c in ascii_crc(self.body)]
            sixes[-1] = (sixes[-1] + self.crc_shift) & 0x3F
            crc = "".join(chr(self.crc_high | six) for six in sixes)
        return self.body + crc + self.end

    def wires(self) -> list[int]:
        """The 8 wire bits of each frame: 7E1 for ASCII (R-4.1-02), raw 8N1 bytes for HB."""
        if self.binary is not None:
            return list(self.binary.encode())
        frames = list(encode_7e1(self.text()))
        for index in self.flip_parity:
            if -len(frames) <= index < len(frames):
                frames[index] ^= 0x80
        return frames
