"""An export reads its events' columns once for both channels (issue 22: the capture half
of a fault-matrix row): every byte it writes, and the edges a held .sr gives the decoder,
are what the event-by-event path (``wire_columns`` declining) writes, on awkward traffic,
on events out of order, with the tool's channel or without, in every format."""

from __future__ import annotations

import random
import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from conformance.capture import export as export_module
from conformance.capture import levels
from conformance.capture.export import export_events
from conformance.capture.held_sr import held_edges, held_sr_captures
from conformance.transcript import DUT, TOOL, Event, EventKind
from tests.support.capture_digest import traffic


def written(path: Path, fmt: str) -> object:
    """What a user sees of an export: a .sr's members, a text file's lines (a VCD's date
    line aside: the clock's)."""
    if fmt == "sr":
        with zipfile.ZipFile(path) as zf:
            return {n: zf.read(n) for n in zf.namelist()}
    return [x for x in path.read_text().splitlines() if not x.startswith("$date")]


def both_ways(events, tmp_path, monkeypatch, fmt="sr", **kw):
    """The export by columns and event by event: what each wrote, and its info."""
    out = []
    for way in ("columns", "events"):
        path = tmp_path / f"{way}.{fmt}"
        with monkeypatch.context() as m:
            if way == "events":
                m.setattr(export_module, "wire_columns", lambda events: None)
            info = export_events(events, str(path), fmt, **kw)
        out.append((written(path, fmt), info.t0, info.samples))
    return out


@pytest.mark.parametrize("seed", [1, 4, 9])
@pytest.mark.parametrize("fmt", ["sr", "vcd", "csv"])
def test_export_by_columns_writes_what_event_by_event_does(seed, fmt, tmp_path, monkeypatch):
    events = traffic(seed, seconds=3.0)
    assert levels.wire_columns(events) is not None
    columns, one_by_one = both_ways(events, tmp_path, monkeypatch, fmt, tool_channel=True)
    assert columns == one_by_one


def shuffled_a_little(events: list[Event], seed: int) -> list[Event]:
    """Neighbours swapped here and there, and equal starts (the stable sort's order kept)."""
    rng = random.Random(seed)
    out = list(events)
    for i in range(0, len(out) - 1, 7):
        if rng.random() < 0.5:
            out[i], out[i + 1] = out[i + 1], out[i]
    twin = replace(out[40], origin=DUT if out[40].origin == TOOL else TOOL, wire=0x55)
    return [*out[:41], twin, *out[41:]]


@pytest.mark.parametrize("tool_channel", [True, False])
def test_export_by_columns_of_events_out_of_order(tool_channel, tmp_path, monkeypatch):
    events = shuffled_a_little(traffic(5, seconds=3.0), 5)
    columns = levels.wire_columns(events)
    assert columns is not None
    starts = [e.start for e in columns.events]
    assert starts == sorted(starts)
    assert columns.events == sorted(
        (e for e in events if e.kind is not EventKind.NOTE), key=lambda e: e.start
    )
    columns_, one_by_one = both_ways(events, tmp_path, monkeypatch, tool_channel=tool_channel)
    assert columns_ == one_by_one


def test_held_export_gives_the_decoder_the_same_edges(tmp_path, monkeypatch):
    """A held .sr (the matrix's round trip): per channel, the same first level and edge
    chunks the decoder reads, both ways."""
    events = traffic(6, seconds=3.0)
    got = []
    for way in ("columns", "events"):
        path = tmp_path / f"{way}.sr"
        with held_sr_captures(), monkeypatch.context() as m:
            if way == "events":
                m.setattr(export_module, "wire_columns", lambda events: None)
            export_events(events, str(path), "sr", tool_channel=True, hold=True)
            for channel in ("SDI12", "TOOL_TX"):
                edges = held_edges(str(path), channel, 1 << 16)
                assert edges is not None
                got.append((way, channel, edges.initial_level, list(edges.chunks)))
    half = len(got) // 2
    assert [g[1:] for g in got[:half]] == [g[1:] for g in got[half:]]
    assert sum(len(c) for c in got[0][3]) > 1000


def test_columns_decline_times_python_and_numpy_would_order_apart():
    """Int or NaN times, or a kind that is not an EventKind, are left to the event by event
    path (whose comparisons Python makes); plain floats are taken."""
    events = traffic(2, seconds=1.0)
    assert levels.wire_columns(events) is not None
    assert levels.wire_columns([*events, Event(EventKind.CHAR, DUT, 2, 3.0, 0x30)]) is None
    nan = Event(EventKind.CHAR, DUT, float("nan"), 3.0, 0x30)
    assert levels.wire_columns([*events, nan]) is None
    assert levels.wire_columns([e for e in events if e.kind is EventKind.NOTE]) is None


def test_columns_mask_is_the_channel_of_those_events():
    """A mask over the columns gives the edges of those events alone."""
    events = traffic(3, seconds=2.0)
    columns = levels.wire_columns(events)
    assert columns is not None
    tool = np.array([e.origin == TOOL for e in columns.events])
    rate, t0 = 100_000.0, 0.0
    alone = levels.edge_array([e for e in columns.events if e.origin == TOOL], rate, t0)
    assert np.array_equal(columns.edges(rate, t0, tool), alone)
    assert np.array_equal(columns.edges(rate, t0), levels.edge_array(columns.events, rate, t0))
