"""A .sr export held without its samples (the fault matrix's round trip, issue 22) reads back
as the written file does: the same edges in the same chunks, the same decode."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from conformance import emulator
from conformance.capture import sigrok, writers
from conformance.capture.decode import decode_capture
from conformance.capture.errors import CaptureError
from conformance.capture.export import TOOL_CHANNEL, export_events
from conformance.capture.held_sr import held_sr_captures, hold_sr
from conformance.capture.writers import Channel, write_sr
from conformance.protocol import commands as cmds
from conformance.tool_recorder import ToolRecorder
from conformance.transcript import EventKind


def _read(path: str, channel: str | None) -> tuple:
    got = sigrok.read_sr(path, channel)
    chunks = [list(c) for c in got.chunks]
    return (
        got.channel, got.channels, got.tick_rate, got.period, got.initial_level, chunks,
        got.end(), got.notes,
    )  # fmt: skip


@pytest.mark.parametrize("member, block", [(997, 997), (997, 400), (500, 1500)])
@pytest.mark.parametrize("seed", range(6))
def test_held_edges_are_the_written_files_chunk_for_chunk(
    tmp_path, monkeypatch, member, block, seed
):
    """Edges with repeats (cancelling in pairs), at or before tick 0 (the first level),
    going back, at and past the end, on block starts: what read_sr finds in the samples
    write_sr wrote, for each channel and for the channel it chooses itself."""
    monkeypatch.setattr(writers, "BLOCK_SAMPLES", member)
    monkeypatch.setattr(sigrok, "BLOCK_SAMPLES", block)
    rng = np.random.default_rng(seed)
    total = int(rng.integers(1, 6000))
    channels = []
    for name, idle in (("SDI12", 1), ("TOOL_TX", 1), ("OTHER", 0)):
        n = int(rng.integers(0, 400))
        ticks = np.sort(rng.integers(-3, total + 5, n))
        ticks = np.concatenate([ticks, [0, 0, member, member, block, total, total + 1]])
        if rng.random() < 0.5:
            ticks = np.sort(ticks)
        if rng.random() < 0.3:
            ticks = ticks[::-1].copy()  # going back: counted where the one before it was
        channels.append(Channel(name, idle, ticks.astype(np.int64)))
    written, held = str(tmp_path / "written.sr"), str(tmp_path / "held.sr")
    write_sr(written, channels, 1e5, total, comment="c")
    write_sr(held, channels, 1e5, total, comment="c", samples=False)
    with held_sr_captures():
        hold_sr(held, channels, 1e5, total)
        for name in (None, "SDI12", "TOOL_TX", "OTHER"):
            sigrok._OTHERS.clear()
            want = _read(written, name)
            sigrok._OTHERS.clear()
            assert _read(held, name) == want
        sigrok._OTHERS.clear()
        with pytest.raises(CaptureError, match="no channel 'X'"):
            sigrok.read_sr(held, "X")


@pytest.fixture(scope="module")
def faulty_run() -> list:
    """0I!, 0M!, 0D0! with a timing fault, the run's events as an export takes them."""
    _, link, _ = emulator.sim_sensor(faults=["response-too-late"])
    master = ToolRecorder(link)
    master.identify()
    master.measure(cmds.measure("0"))
    return [e for e in link.transcript.events if e.kind is not EventKind.NOTE]


def test_a_held_export_decodes_as_the_written_one(tmp_path, faulty_run):
    """The matrix's export (the tool's TX on a second channel) decoded as ``judge`` decodes
    it: held, every event, count and note is the written file's."""
    written, held = tmp_path / "written.sr", tmp_path / "held.sr"
    export_events(faulty_run, str(written), tool_channel=True)
    with held_sr_captures():
        export_events(faulty_run, str(held), tool_channel=True, hold=True)
        assert held.stat().st_size < written.stat().st_size  # no sample member
        got = decode_capture(str(held), tx_channel=TOOL_CHANNEL, keep=False)
    want = decode_capture(str(written), tx_channel=TOOL_CHANNEL, keep=False)
    assert got.events == want.events and len(got.events) > 20
    assert dataclasses.replace(got, path="", problems=[]) == dataclasses.replace(
        want, path="", problems=[]
    )
    assert got.problems == want.problems


def test_a_held_export_is_let_go(tmp_path, faulty_run):
    """Past :func:`held_sr_captures` the file holds no samples, and reading it says so
    (never edges of another run)."""
    path = tmp_path / "held.sr"
    with held_sr_captures():
        export_events(faulty_run, str(path), tool_channel=True, hold=True)
    with pytest.raises(CaptureError, match="no sample data"):
        sigrok.read_sr(str(path), None)


def test_only_a_sigrok_export_is_held(tmp_path, faulty_run):
    with pytest.raises(ValueError, match="only a .sr export"):
        export_events(faulty_run, str(tmp_path / "x.vcd"), hold=True)
