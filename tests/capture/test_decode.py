"""The capture decoder on real captures nobody here made (../shared/captures, sigrok-dumps):
every frame decodes to the known text with no framing or parity error, and agrees with
sigrok's own UART decoder character for character and in start sample."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from conformance.capture import decode_capture
from tests.support.paths import SHARED

CAPTURES = SHARED / "captures"
TEXT = "Hello World!\r\n"
CASES = [
    ("hello_world_8n1_1200.sr", 1200, "8N1"),
    ("hello_world_8n1_9600.sr", 9600, "8N1"),
    ("hello_world_7e1_115200.sr", 115200, "7E1"),
    ("hello_world_7o1_115200.sr", 115200, "7O1"),
]
IDS = [c[0] for c in CASES]


def capture(name: str) -> Path:
    path = CAPTURES / name
    if not path.exists():
        pytest.skip(f"shared capture {path} is not there")
    return path


def text_of(decoded) -> str:
    mask = 0x7F if decoded.framing[0] == "7" else 0xFF
    return "".join(chr(e.wire & mask) for e in decoded.events)


@pytest.mark.parametrize(("name", "baud", "framing"), CASES, ids=IDS)
def test_real_capture_decodes_exactly(name, baud, framing):
    d = decode_capture(capture(name), baud=baud, framing=framing)
    assert d.chars == 56 and len(d.events) == 56
    assert (d.framing_errors, d.parity_errors, d.glitches, d.breaks, d.pulses) == (0, 0, 0, 0, 0)
    assert text_of(d) == TEXT * 4
    assert not d.inverted and d.polarity_detected
    assert d.channel == "TX" and d.channels == ["TX"]
    lo, median, hi = d.baud_error_summary()
    # one sample at 1 MHz is 11 % of a 115200 baud bit: per frame the rate is known to ~2 %
    assert abs(median) < 0.5 and lo > -3 and hi < 3
    assert d.uncertainty_s == pytest.approx(1 / d.sample_rate)
    # characters start whole frames apart, plus the sender's own idle gaps (never less)
    frame = 10 / baud
    for a, b in zip(d.events, d.events[1:], strict=False):
        assert b.start - a.start >= frame - 2 * d.uncertainty_s


@pytest.mark.parametrize(("name", "baud", "framing"), CASES, ids=IDS)
def test_real_capture_agrees_with_sigrok_cli(name, baud, framing):
    if shutil.which("sigrok-cli") is None:
        pytest.skip("sigrok-cli is not installed (Debian package sigrok-cli)")
    path = capture(name)
    parity = {"N": "none", "E": "even", "O": "odd"}[framing[1]]
    decoder = f"uart:baudrate={baud}:rx=TX:data_bits={framing[0]}:parity={parity}"
    out = subprocess.run(
        [
            "sigrok-cli",
            "-i",
            str(path),
            "-P",
            decoder,
            "-A",
            "uart=rx-start:rx-data",
            "--protocol-decoder-samplenum",
        ],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    ).stdout
    starts = [int(m) for m in re.findall(r"^(\d+)-\d+ uart-1: Start bit$", out, re.M)]
    values = [int(v, 16) for v in re.findall(r"^\d+-\d+ uart-1: ([0-9A-F]{2})$", out, re.M)]
    assert len(starts) == len(values) == 56
    d = decode_capture(path, baud=baud, framing=framing)
    mask = 0x7F if framing[0] == "7" else 0xFF
    assert [e.wire & mask for e in d.events] == values
    for e, s in zip(d.events, starts, strict=True):
        assert abs(round(e.start * d.sample_rate) - s) <= 1


def test_sigrok_cli_reads_our_export(tmp_path):
    """The .sr we write opens in libsigrok (what PulseView is built on) and sigrok's own UART
    decoder reads the same characters from it."""
    if shutil.which("sigrok-cli") is None:
        pytest.skip("sigrok-cli is not installed (Debian package sigrok-cli)")
    from conformance.capture import export_events
    from conformance.transcript import TOOL, Event, EventKind, to_wire_7e1

    events, t = [], 0.03
    for c in "0M!0+1.5-2\r\n":
        events.append(Event(EventKind.CHAR, TOOL, t, t + 10 / 1200, wire=to_wire_7e1(ord(c))))
        t += 10 / 1200 + 0.001
    path = tmp_path / "ours.sr"
    export_events(events, path, tool_channel=True)
    out = subprocess.run(
        [
            "sigrok-cli",
            "-i",
            str(path),
            "-P",
            "uart:baudrate=1200:rx=SDI12:data_bits=7:parity=even",
            "-A",
            "uart=rx-data",
        ],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    ).stdout
    values = [int(v, 16) for v in re.findall(r"uart-1: ([0-9A-F]{2})$", out, re.M)]
    assert values == [e.wire & 0x7F for e in events]
