"""Reading a sigrok session: a probe read by name after a whole read of another one is taken
from the edges that read kept (``sigrok.KEPT_EDGES``), exactly as reading it again gives it."""

from __future__ import annotations

import os

import pytest

from conformance.capture import sigrok
from conformance.capture.edges import Edges
from conformance.capture.export import export_events
from conformance.capture.writers import Channel, write_sr
from conformance.transcript import DUT, Event, EventKind
from tests.support.capture_digest import traffic


def seen(edges: Edges) -> tuple:
    """Everything a decoder gets from ``edges`` (the chunks flattened: their cut is free)."""
    ticks = [t for chunk in edges.chunks for t in chunk]
    return (
        edges.channel, edges.channels, edges.tick_rate, edges.period, edges.initial_level,
        ticks, edges.t0, edges.end(), edges.notes,
    )  # fmt: skip


def fresh(path: str, channel: str | None) -> tuple:
    sigrok._KEPT = None
    return seen(sigrok.read_sr(path, channel))


@pytest.fixture
def session(tmp_path, monkeypatch) -> str:
    """Three probes over many small blocks (edges on block bounds too), the third idle low."""
    monkeypatch.setattr(sigrok, "BLOCK_SAMPLES", 997)
    monkeypatch.setattr(sigrok, "_KEPT", None)
    path = str(tmp_path / "three.sr")
    events = traffic(5, seconds=1.5)
    export_events(events, path, "sr", tool_channel=True)
    bus = seen(sigrok.read_sr(path, "SDI12"))[5]
    edges = sorted({*bus[::3], *range(0, 60_000, 997), *range(1, 60_000, 997)})
    write_sr(
        path, [Channel("A", 1, bus), Channel("B", 0, edges), Channel("C", 1, [])], 1e5, 150_000
    )
    sigrok._KEPT = None  # what reading the export kept
    return path


@pytest.mark.parametrize("first", ["A", "B", "C", None])
def test_a_probe_kept_from_a_whole_read_is_the_probe_read_again(session, first):
    want = {name: fresh(session, name) for name in ("A", "B", "C")}
    sigrok._KEPT = None
    seen(sigrok.read_sr(session, first))  # the whole read that keeps the others
    for name in ("A", "B", "C"):
        if name != (first or "B"):  # None reads the busiest: B
            kept = sigrok._KEPT
            assert kept is not None and name in kept.ticks
            assert seen(sigrok.read_sr(session, name)) == want[name]
            assert name not in kept.ticks  # taken once


def test_a_read_cut_short_keeps_nothing(session):
    """A read left after its first chunk (its reader a few blocks ahead, then stopped)."""
    chunks = sigrok.read_sr(session, "A").chunks
    next(chunks)  # type: ignore[call-overload]
    chunks.close()  # type: ignore[attr-defined]
    assert sigrok._KEPT is None
    assert seen(sigrok.read_sr(session, "B")) == fresh(session, "B")


def test_a_changed_file_is_read_again(session):
    seen(sigrok.read_sr(session, "A"))
    write_sr(session, [Channel("A", 1, [5, 9]), Channel("B", 1, [7, 8, 40])], 1e5, 500)
    os.utime(session, ns=(1, 1))  # a new mtime whatever the clock's grain
    got = seen(sigrok.read_sr(session, "B"))
    assert got[5] == [7, 8, 40] and got == fresh(session, "B")


def test_past_the_bound_nothing_is_kept(session, monkeypatch):
    monkeypatch.setattr(sigrok, "KEPT_EDGES", 10)
    seen(sigrok.read_sr(session, "A"))
    assert sigrok._KEPT is None
    assert seen(sigrok.read_sr(session, "B")) == fresh(session, "B")


def test_a_bus_decoded_with_its_tool_channel_is_as_without_the_kept_edges(tmp_path):
    """decode_capture with a TX channel (the round trip's judging) gives the same decode
    whether the TX channel's edges were kept from the bus channel's read or read again."""
    from conformance.capture import decode as capture_decode

    path = str(tmp_path / "run.sr")
    events = traffic(11, seconds=4.0) + [Event(EventKind.CHAR, DUT, 4.5, 4.5083, 0x41)]
    export_events(events, path, "sr", tool_channel=True)
    capture_decode._LAST = None
    kept = capture_decode.decode_capture(path, tx_channel="TOOL_TX")
    capture_decode._LAST = None
    sigrok._KEPT = None
    read = []
    real = sigrok._kept_edges
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sigrok, "_kept_edges", lambda *a: read.append(a[1]) and None)
        again = capture_decode.decode_capture(path, tx_channel="TOOL_TX")
    assert read == ["TOOL_TX"] and real is sigrok._kept_edges
    assert kept.events == again.events and kept.notes == again.notes
    assert kept.problems == again.problems and list(kept.baud_error_pct) == list(
        again.baud_error_pct
    )
