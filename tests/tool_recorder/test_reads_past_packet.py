"""An observer reads an aHB! collection on past an unreadable packet (issue 22, ninth round:
R-5.2-04 PASSed on aDB0! alone when a size field sent high byte first made it unreadable),
but not past the empty packet, a repeated packet, or as many packets as values announced."""

from __future__ import annotations

from conformance.protocol.binary import DataType, build_packet, empty_packet
from conformance.tool_recorder.validity import reads_past_packet

BIG_ENDIAN = b"1\x00\x04\x01\x80\xff\x00\x7f\x67\x40"  # 4 bytes whose size reads as 1024


def test_reads_on_past_an_unreadable_packet_only():
    assert reads_past_packet([BIG_ENDIAN], 233)
    assert not reads_past_packet([empty_packet("1")], 233)
    assert not reads_past_packet([b"1\x00\x00\x00"], 233)  # too short to be a packet at all
    assert not reads_past_packet([BIG_ENDIAN, BIG_ENDIAN], 233)  # the sensor does not advance
    other = build_packet("1", DataType.INT8, [1, 2, 3])
    assert reads_past_packet([other, BIG_ENDIAN], 233)
    assert not reads_past_packet([other, BIG_ENDIAN], 2)  # 2 values fit no third packet
