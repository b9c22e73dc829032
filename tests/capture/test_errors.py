"""Bad input: every capture the decoder cannot use raises CaptureError naming the file and
what is wrong with it (the CLI makes that exit 4 with no traceback)."""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import pytest

from conformance.capture import (
    CaptureError,
    decode_capture,
    export_events,
    read_transcript_jsonl,
    sniff,
)
from conformance.protocol.timing import BIT_TIME
from conformance.transcript import TOOL, Event, EventKind, to_wire_7e1
from tests.support.paths import SHARED

CAPTURES = SHARED / "captures"


def hello(baud: int = 1200) -> Path:
    path = CAPTURES / f"hello_world_8n1_{baud}.sr"
    if not path.exists():
        pytest.skip(f"shared capture {path} is not there")
    return path


def some_events() -> list[Event]:
    out = [Event(EventKind.BREAK, TOOL, 0.03, 0.043)]
    t = 0.06
    for c in "0I!":
        out.append(Event(EventKind.CHAR, TOOL, t, t + 10 * BIT_TIME, wire=to_wire_7e1(ord(c))))
        t += 10 * BIT_TIME
    return out


def fails(path, match: str, **kw) -> CaptureError:
    with pytest.raises(CaptureError, match=match) as info:
        decode_capture(path, **kw)
    assert info.value.path == str(path)
    assert str(info.value).startswith(f"{path}: ")
    return info.value


def test_truncated_zip(tmp_path):
    data = hello().read_bytes()
    path = tmp_path / "cut.sr"
    path.write_bytes(data[: len(data) // 2])
    fails(path, "not a readable sigrok session")


def test_corrupt_samples_inside_the_zip(tmp_path):
    src = hello().read_bytes()
    path = tmp_path / "corrupt.sr"
    # flip bytes in the middle of the compressed samples, keeping the zip directory intact
    mid = len(src) // 2
    path.write_bytes(src[:mid] + bytes(b ^ 0x5A for b in src[mid : mid + 64]) + src[mid + 64 :])
    fails(path, "corrupt sample data in 'logic-1-1'", baud=1200, framing="8N1")


def test_no_transitions(tmp_path):
    path = tmp_path / "flat.sr"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("version", "2")
        zf.writestr(
            "metadata",
            "[device 1]\ncapturefile=logic-1\ntotal probes=1\nsamplerate=1 MHz\n"
            "probe1=SDI12\nunitsize=1\n",
        )
        zf.writestr("logic-1-1", b"\x01" * 10000)
    fails(path, "'SDI12' never changes level")
    csv = tmp_path / "flat.csv"
    csv.write_text("Time [s],Channel 0\n0.000000000,1\n")
    fails(csv, "never changes level")


def test_wrong_channel_lists_the_ones_present(tmp_path):
    err = fails(hello(), r"no channel 'RX'; channels present: TX", channel="RX", framing="8N1")
    assert "TX" in err.what
    path = tmp_path / "two.vcd"
    export_events(some_events(), path, tool_channel=True)
    fails(path, "channels present: SDI12, TOOL_TX", channel="D0")
    csv = tmp_path / "two.csv"
    export_events(some_events(), csv, tool_channel=True)
    fails(csv, "channels present: SDI12, TOOL_TX", channel="D0")


def test_wrong_baud(tmp_path):
    fails(hello(1200), "wrong bit rate.*about 1202 baud", baud=9600, framing="8N1")
    fails(hello(9600), "wrong bit rate.*about 9615 baud", baud=1200, framing="8N1")


def test_binary_garbage(tmp_path):
    path = tmp_path / "garbage.sr"
    path.write_bytes(os.urandom(4096) + b"\0")
    fails(path, "binary data")


@pytest.mark.parametrize("lead", [b"{", b" \t{", b"$date", b"time,"])
def test_binary_garbage_that_starts_like_a_text_format(tmp_path, lead):
    """Random bytes whose first characters spell a text format's start are binary data, not
    a transcript, VCD or CSV (CI drew such a file once: 'a transcript, not a capture')."""
    path = tmp_path / "garbage.sr"
    path.write_bytes(lead + bytes(range(128, 256)) * 16)
    fails(path, "binary data")


def test_unknown_text_format(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("just some text\nthat is no capture\n")
    fails(path, "unknown format")


def test_empty_and_missing_files(tmp_path):
    empty = tmp_path / "empty.vcd"
    empty.write_bytes(b"")
    fails(empty, "empty file")
    fails(tmp_path / "missing.sr", "cannot read")


def test_zip_that_is_not_a_session(tmp_path):
    path = tmp_path / "other.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("readme.txt", "hello")
    fails(path, "without a 'metadata' member")


def test_bad_vcd_and_csv(tmp_path):
    vcd = tmp_path / "cut.vcd"
    vcd.write_text("$timescale 1 us $end\n$scope module x $end\n$var wire 1 ! TX $end\n")
    fails(vcd, "enddefinitions")
    csv = tmp_path / "bad.csv"
    csv.write_text("Time [s],TX\n0.0,1\n0.001,0\nnot-a-time,1\n")
    fails(csv, "line 4")
    csv.write_text("Time [s],TX\n0.0,1\n0.001,0\n0.0005,1\n")
    fails(csv, "time goes backwards")


def test_bad_options(tmp_path):
    fails(hello(), "framing '9N2'", framing="9N2")
    fails(hello(), "not a bit rate", baud=0)


def test_transcript_is_not_a_capture(tmp_path):
    path = tmp_path / "transcript.jsonl"
    path.write_text('{"kind": "char", "origin": "tool", "start": 0, "end": 0.008}\n')
    assert sniff(path) == "jsonl"
    fails(path, "a transcript, not a capture")
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"kind": "char", "origin": "tool", "start": 0, "end": 0.008}\n{"kind": 5}\n')
    with pytest.raises(CaptureError, match="line 2: not a transcript event"):
        read_transcript_jsonl(bad)


def test_export_rejects_what_it_cannot_write(tmp_path):
    with pytest.raises(ValueError, match="format 'wav'"):
        export_events(some_events(), tmp_path / "x.wav")
    with pytest.raises(ValueError, match="no characters or breaks"):
        export_events([], tmp_path / "x.sr")
    with pytest.raises(ValueError, match="1, 10 or 100 units"):
        export_events(some_events(), tmp_path / "x.vcd", sample_rate=3e5)


def test_force_judges_a_decode_the_check_would_refuse_and_keeps_why():
    """``judge --force``: a capture that looks like the wrong bit rate is decoded anyway (a
    user who knows the bus better than the check), the refusal kept for the notes."""
    fails(hello(1200), r"--force judges it anyway", baud=9600, framing="8N1")
    forced = decode_capture(hello(1200), baud=9600, framing="8N1", force=True)
    assert forced.forced_past is not None and "wrong bit rate" in forced.forced_past
    assert forced.events  # what decoded is there to judge
    assert decode_capture(hello(1200), framing="8N1").forced_past is None
