"""The capture path pinned bit for bit: export samples and decoded output against digests the
code gave before issue 22's speed-up (``data/capture_golden.json``), so a faster export,
decoder or transcript reader that moves one edge, one time or one diagnostic fails here.

To regenerate after a deliberate change of behaviour (never for a speed-up):
``python -m tests.e2e.test_capture_golden`` prints the new file.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance.capture import decode_capture, export_events
from tests.support.capture_digest import (  # noqa: E402
    decode_digest,
    golden,
    samples_digest,
    text_digest,
    traffic,
)
from tests.support.paths import SHARED

SHARED = SHARED / "captures"

#: (name, seed, sample rate, line polarity): exports of seeded hostile traffic
EXPORTS = [
    ("busy-100k-uart", 1, 100_000.0, False),
    ("busy-100k-line", 2, 100_000.0, True),
    ("busy-1M-uart", 3, 1_000_000.0, False),
    ("busy-625k-line", 4, 625_000.0, True),
    ("busy-48k-uart", 5, 48_000.0, False),
]

#: (file, baud, framing) of the real captures in ../shared/captures
REAL = [
    ("hello_world_8n1_1200.sr", 1200, "8N1"),
    ("hello_world_8n1_9600.sr", 9600, "8N1"),
    ("hello_world_7e1_115200.sr", 115200, "7E1"),
    ("hello_world_7o1_115200.sr", 115200, "7O1"),
]


def digests_of_export(name: str, seed: int, rate: float, line: bool, tmp: Path) -> dict:
    """The samples of the export and its decode with and without the TX channel."""
    path = tmp / f"{name}.sr"
    events = traffic(seed)
    texts = {}
    for fmt in ("vcd", "csv") if rate in (1e5, 1e6) else ("csv",):  # VCD: 1, 10, 100 units
        other = tmp / f"{name}.{fmt}"
        export_events(events, other, fmt, sample_rate=rate, line_polarity=line, tool_channel=True)
        texts[fmt] = text_digest(other)
    export_events(events, path, "sr", sample_rate=rate, line_polarity=line, tool_channel=True)
    return texts | {
        "samples": samples_digest(path),
        "decode": decode_digest(decode_capture(path, channel="SDI12")),
        "decode-tx": decode_digest(decode_capture(path, tx_channel="TOOL_TX")),
    }


#: emulator faults whose exchanges are exported and decoded (none: a conforming sensor)
SIM_FAULTS = ["none", "fast-baud", "parity-error", "inter-char-gap", "non-printable-char"]


def digests_of_sim(fault: str, tmp: Path) -> dict:
    """0I!, 0M!, 0D0! with the emulator (virtual time: the same events every run), exported
    with the tool's TX channel and decoded with it."""
    from conformance import emulator
    from conformance.protocol import commands as cmds
    from conformance.tool_recorder import ToolRecorder
    from conformance.transcript import EventKind

    _, link, _ = emulator.sim_sensor(faults=[] if fault == "none" else [fault])
    master = ToolRecorder(link)
    master.identify()
    master.measure(cmds.measure("0"))
    events = [e for e in link.transcript.events if e.kind is not EventKind.NOTE]
    path = tmp / f"sim-{fault}.sr"
    export_events(events, path, "sr", tool_channel=True)
    return {
        "samples": samples_digest(path),
        "decode-tx": decode_digest(decode_capture(path, tx_channel="TOOL_TX")),
    }


def digest_of_real(file: str, baud: int, framing: str) -> str:
    return decode_digest(decode_capture(SHARED / file, baud=baud, framing=framing))


@pytest.mark.parametrize("name,seed,rate,line", EXPORTS, ids=[e[0] for e in EXPORTS])
def test_export_and_decode_unchanged(name, seed, rate, line, tmp_path):
    assert digests_of_export(name, seed, rate, line, tmp_path) == golden()[name]


@pytest.mark.parametrize("fault", SIM_FAULTS)
def test_sim_exchange_export_and_decode_unchanged(fault, tmp_path):
    assert digests_of_sim(fault, tmp_path) == golden()[f"sim-{fault}"]


@pytest.mark.parametrize("file,baud,framing", REAL, ids=[r[0] for r in REAL])
def test_real_capture_decode_unchanged(file, baud, framing):
    if not (SHARED / file).exists():
        pytest.skip(f"{SHARED / file} is not on this machine")
    assert digest_of_real(file, baud, framing) == golden()[file]


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        out: dict = {e[0]: digests_of_export(*e, Path(tmp)) for e in EXPORTS}
        out |= {f"sim-{f}": digests_of_sim(f, Path(tmp)) for f in SIM_FAULTS}
    out |= {r[0]: digest_of_real(*r) for r in REAL}
    print(json.dumps(out, indent=1, sort_keys=True))
