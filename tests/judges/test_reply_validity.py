"""The recorder judges' own reply-validity rules (issue 10): built on the response grammar,
returning reason codes, and independent of the golden recorder's validity code."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from conformance import view
from conformance.judges import recorder
from conformance.judges.reply_validity import NO_REPLY, Reason, check_packet, check_reply
from conformance.protocol.binary import binary_crc
from conformance.protocol.commands import parse_command
from conformance.protocol.crc import ascii_crc
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1

GAP_LIMIT = CHAR_TIME + 0.4e-3


def reply(text: str, start: float = 0.01, *, parity: bool = True) -> list[Event]:
    events, t = [], start
    for i, c in enumerate(text):
        wire = to_wire_7e1(ord(c))
        if not parity and i == 1:
            wire ^= 0x80
        events.append(Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, wire=wire))
        t += CHAR_TIME
    return events


def reason(command: str, text: str, crc: bool | None = None, **kw) -> Reason | None:
    problem = check_reply(
        parse_command(command),
        reply(text, **kw),
        address=command[0],
        command_end=0.0,
        gap_limit=GAP_LIMIT,
        crc_expected=crc,
    )
    return None if problem is None else problem.reason


@pytest.mark.parametrize(
    ("command", "text", "crc", "expected"),
    [
        ("0!", "0\r\n", None, None),
        ("0M!", "00053\r\n", None, None),
        ("0M!", "00?53\r\n", None, Reason.SHAPE),
        ("0M!", "10053\r\n", None, Reason.ADDRESS),
        ("0I!", "013VENDOR..\r\n", None, None),
        ("0D0!", "0+1.5-2\r\n", False, None),
        ("0D0!", "0+1.5-2", False, Reason.FRAMING),
        ("0D0!", "0+1.5-2" + ascii_crc("0+1.5-2") + "\r\n", True, None),
        ("0D0!", "0+1.5-2AAA\r\n", True, Reason.CRC_WRONG),
        ("0D0!", "0+1.5-2\r\n", True, Reason.CRC_MISSING),
        ("0D0!", "0+3.14" + ascii_crc("0+3.14") + "\r\n", False, Reason.CRC_UNASKED),
        ("0IMC_001!", "0,TA,degC;AAA\r\n", None, Reason.CRC_WRONG),
        ("0IM_001!", "0,TA,degC;\r\n", None, None),
    ],
)
def test_reasons(command, text, crc, expected):
    assert reason(command, text, crc) is expected


def test_timing_reasons():
    assert reason("0!", "0\r\n", start=-0.001) is Reason.CONTENTION
    assert reason("0I!", "013VENDOR..\r\n", parity=False) is Reason.PARITY
    assert check_reply(None, [], address="0", command_end=0.0, gap_limit=1, crc_expected=None) is (
        NO_REPLY
    )


def test_binary_crc_is_a_reason_code():
    packet = b"0\x04\x00\x03" + (1000).to_bytes(2, "little", signed=True) * 2
    good = packet + binary_crc(packet)
    bad = packet + b"\x00\x00"
    events = [
        Event(EventKind.CHAR, DUT, 0.01 + i * CHAR_TIME, 0.02, wire=b) for i, b in enumerate(good)
    ]
    assert check_packet(events, address="0", command_end=0.0) is None
    events = [
        Event(EventKind.CHAR, DUT, 0.01 + i * CHAR_TIME, 0.02, wire=b) for i, b in enumerate(bad)
    ]
    assert check_packet(events, address="0", command_end=0.0).reason is Reason.CRC_WRONG


def test_the_recorder_judges_do_not_use_the_golden_recorders_validity():
    # every module of the recorder judges, and the view they read (except the rebuilding of
    # the tool recorder's records, which is the tool recorder's own reading)
    paths = list(Path(recorder.__file__).parent.glob("*.py"))
    paths += [p for p in Path(view.__file__).parent.glob("*.py") if p.name != "rebuilt_records.py"]
    trees = [ast.parse(p.read_text(encoding="utf-8")) for p in paths]
    imported = {
        f"{node.module}.{alias.name}" if isinstance(node, ast.ImportFrom) else alias.name
        for tree in trees
        for node in ast.walk(tree)
        if isinstance(node, (ast.Import, ast.ImportFrom))
        for alias in node.names
    }
    assert not [name for name in imported if "validity" in name and "reply_validity" not in name]
