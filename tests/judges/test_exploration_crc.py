"""The exploration's CRC check counts R-4.4.12-05 only where the CRC was compared with the
text: one encoded as no CRC-16 (R-4.4.12-06's deviation) is not, so it shows nothing of the
value (crc-missing + crc-wrong-encoding + measure-ttt-two-digits, seed 4198: R-4.4.12-05
PASSed "held over 2 checks" on two such aRCn! replies, no CRC compared in the run)."""

from __future__ import annotations

from conformance.judges.exploration import Observation, judge
from conformance.protocol.crc import ascii_crc


def crc_reply(body: str, *, high: bool = False) -> Observation:
    crc = ascii_crc(body)
    if high:  # crc-wrong-encoding: each character or'ed with 0x60 instead of 0x40
        crc = "".join(chr(ord(c) | 0x60) for c in crc)
    return Observation("crc", "0RC0!", f"{body}{crc}\r\n")


def test_a_compared_crc_checks_value_and_encoding():
    right = judge(crc_reply("0+1.5-2"))
    assert right.checked == ("R-4.4.12-05", "R-4.4.12-06") and right.breach is None


def test_a_crc_encoded_as_no_crc16_is_no_check_of_its_value():
    wrong = judge(crc_reply("0+1.5-2", high=True))
    assert "R-4.4.12-05" not in wrong.checked
    assert wrong.breach is not None and wrong.breach.requirement == "R-4.4.12-06"
