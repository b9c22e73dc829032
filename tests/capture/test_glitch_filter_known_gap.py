"""The glitch filter told the stream's least gap (issue 22, matrix22): a held session knows it
(its ticks are one array), and at or above the filter's width no chunk is searched for a
short pulse. The chunks, the edges and the counters must be what the searching filter gives,
and the least gap a held session states must be the true one (a gap stated too wide would let
a spike through: a glitch the decoder then never reports)."""

from __future__ import annotations

import random

import pytest

from conformance import emulator
from conformance.capture import glitch_filter
from conformance.capture.decode import decode_capture
from conformance.capture.export import BUS_CHANNEL, TOOL_CHANNEL, export_events
from conformance.capture.formats import read_edges
from conformance.capture.glitch_filter import GlitchFilter
from conformance.capture.held_sr import held_sr_captures
from conformance.protocol import commands as cmds
from conformance.tool_recorder import ToolRecorder
from conformance.transcript import EventKind


def _stream(rng: random.Random) -> tuple[list[int], list[list[int]]]:
    """Strictly rising edges (mostly bit-long runs, now and then a short gap) cut into
    chunks of random sizes, some empty."""
    steps = [833] * 20 + [1666, 4000, 1, 3, 5, 9, 10, 11]
    edges, t = [], rng.randrange(0, 50)
    for _ in range(rng.randrange(0, 200)):
        t += rng.choice(steps)
        edges.append(t)
    chunks, at = [], 0
    while at < len(edges) or not chunks:
        size = rng.choice([0, 1, 2, 5, 40, 500])
        chunks.append(edges[at : at + size])
        at += size
    return edges, chunks


def _filtered(width: float, chunks: list[list[int]], min_gap: int | None) -> tuple:
    f = GlitchFilter(width)
    out = [list(c) for c in f(iter(chunks), min_gap)]
    return out, f.removed, f.beside_edges


@pytest.mark.parametrize("seed", range(300))
def test_a_known_least_gap_gives_the_searching_filters_chunks(seed):
    """Any stream, any chunking, any width: told the true least gap, the filter gives the
    chunks (not only the edges) and counts it gives when it searches every chunk."""
    rng = random.Random(seed)
    edges, chunks = _stream(rng)
    gaps = [b - a for a, b in zip(edges, edges[1:], strict=False)]
    least = min(gaps) if gaps else None
    for width in (0, 1, 5, 10.5, 833, 900):
        assert _filtered(width, chunks, least) == _filtered(width, chunks, None)


def test_a_known_least_gap_is_not_searched_for(monkeypatch):
    """At or above the width the chunks are re-cut with no gap looked at (the scan the
    known gap spares: ``min`` over each chunk's gaps); below it the filter searches."""
    chunks = [[0, 833, 1666], [2499, 3332], [4165]]
    scans = []

    def counted(*args, **kwargs):
        scans.append(1)
        return min(*args, **kwargs)

    monkeypatch.setattr(glitch_filter, "min", counted, raising=False)
    assert _filtered(10, chunks, 833) == ([[0, 833], [1666, 2499], [3332], [4165]], 0, 0)
    assert scans == []
    assert _filtered(10, chunks, 5)[0] == [[0, 833], [1666, 2499], [3332], [4165]]
    assert scans


@pytest.fixture(scope="module")
def sim_runs() -> list[list]:
    """A clean sim session and one with a timing fault, as an export takes their events."""
    runs = []
    for faults in ([], ["response-too-late"]):
        _, link, _ = emulator.sim_sensor(faults=faults)
        master = ToolRecorder(link)
        master.identify()
        master.measure(cmds.measure("0"))
        runs.append([e for e in link.transcript.events if e.kind is not EventKind.NOTE])
    return runs


@pytest.mark.parametrize("run", [0, 1])
def test_a_held_session_states_its_true_least_gap(tmp_path, monkeypatch, sim_runs, run):
    """Each channel of a held export states the least gap its chunks really have, and its
    decode (told it) is the decode of the same edges with no gap stated."""
    path = str(tmp_path / "run.sr")
    with held_sr_captures():
        export_events(sim_runs[run], path, tool_channel=True, hold=True)
        for channel in (BUS_CHANNEL, TOOL_CHANNEL):
            edges = read_edges(path, channel, "sr")
            ticks = [t for c in edges.chunks for t in c]
            assert len(ticks) > 20
            assert edges.min_gap == min(b - a for a, b in zip(ticks, ticks[1:], strict=False))
        told = decode_capture(path, tx_channel=TOOL_CHANNEL, keep=False)
        unknown = _decoded_without_gap(path, monkeypatch)
    assert told.events == unknown.events and len(told.events) > 20
    assert told == unknown


def _decoded_without_gap(path: str, monkeypatch: pytest.MonkeyPatch):
    """The capture decoded as if its reader did not know the least gap."""
    from conformance.capture import decode as decode_module

    real = decode_module.read_edges

    def unknown(*args, **kwargs):
        edges = real(*args, **kwargs)
        edges.min_gap = None
        return edges

    with monkeypatch.context() as m:
        m.setattr(decode_module, "read_edges", unknown)
        return decode_capture(path, tx_channel=TOOL_CHANNEL, keep=False)


def test_a_spike_makes_the_stated_gap_too_short_to_skip_the_search(tmp_path, sim_runs):
    """A held export with a one-tick pulse on the bus: its stated least gap is that pulse,
    below the filter's width, so the filter searches and removes it as before."""
    events = sim_runs[0]
    chars = [e for e in events if e.kind is EventKind.CHAR]
    spike = chars[len(chars) // 2]
    later = spike.end + 0.05  # on the idle line after a character, 10 us long
    glitchy = [*events, emulator_event(later, later + 1e-5)]
    path = str(tmp_path / "spike.sr")
    with held_sr_captures():
        export_events(glitchy, path, tool_channel=True, hold=True)
        edges = read_edges(path, BUS_CHANNEL, "sr")
        assert edges.min_gap == 1
        decoded = decode_capture(path, tx_channel=TOOL_CHANNEL, keep=False)
    assert decoded.filtered >= 1


def emulator_event(start: float, end: float):
    """A break-kind pulse on the bus (the export draws it as the line held spacing)."""
    from conformance.transcript import DUT, full_event

    return full_event(EventKind.BREAK, DUT, start, end, 0, "", 0.0, None)
