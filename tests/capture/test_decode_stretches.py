"""The decoder's collection taking a stretch of certified frames whole
(``capture.decode._stretches``, ``_origins``: columns and marks extended by slices, the TX
matching by one search) gives what it gave frame by frame: the same columns and origins,
marks, problems, bit-rate errors and counters, on exported hostile traffic and on a
fault-matrix row's capture; and the search gives the walk's origins wherever it answers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture import decode as decode_module
from conformance.capture.decode import Marks, _origins, _TxArrays, decode_capture
from conformance.capture.export import export_events
from conformance.capture.uart import Framing
from conformance.capture.uart_bulk import Batch
from conformance.matrices.roundtrip import live_run
from conformance.transcript import EventKind
from tests.support.capture_digest import traffic


def _decoded(path: str, monkeypatch, stretch_min: int):
    monkeypatch.setattr(decode_module, "STRETCH_MIN", stretch_min)
    tx = Marks()
    out = decode_capture(path, tx_channel="TOOL_TX", columns=True, keep=False)
    tx_out = decode_module._decode_channel(
        path, "sr", "TOOL_TX", None, decode_module.DecodeSettings(1200, SEVEN_E1), into=tx
    )
    return out, tx, tx_out


SEVEN_E1 = Framing.parse("7E1")


def _same(a, b) -> None:
    ca, cb = a.columns, b.columns
    assert ca is not None and cb is not None
    assert [list(map(repr, x)) for x in (ca.start, ca.end)] == [
        list(map(repr, x)) for x in (cb.start, cb.end)
    ]
    assert (ca.wire, ca.origin, ca.made) == (cb.wire, cb.origin, cb.made)
    assert a.problems == b.problems
    assert [repr(x) for x in a.baud_error_pct] == [repr(x) for x in b.baud_error_pct]
    fields = ("chars", "framing_errors", "parity_errors", "glitches", "breaks", "pulses")
    assert [getattr(a, f) for f in fields] == [getattr(b, f) for f in fields]
    assert (a.partial_frames, a.notes) == (b.partial_frames, b.notes)


@pytest.mark.parametrize("seed", [1, 4, 9])
def test_stretches_give_what_frame_by_frame_gave(seed, tmp_path, monkeypatch):
    path = str(tmp_path / "run.sr")
    export_events(traffic(seed, seconds=6.0), path, "sr", tool_channel=True)
    whole, tx_whole, txd_whole = _decoded(path, monkeypatch, 16)
    one, tx_one, txd_one = _decoded(path, monkeypatch, 10**9)
    _same(whole, one)
    assert (tx_whole.start, tx_whole.kind, tx_whole.wire) == (
        tx_one.start,
        tx_one.kind,
        tx_one.wire,
    )
    assert txd_whole.problems == txd_one.problems and txd_whole.chars == txd_one.chars
    assert RECORDER in whole.columns.origin  # the TX matched some: the search was exercised


RECORDER = decode_module.RECORDER_ORIGIN


def test_a_sim_runs_capture_is_the_same_taken_in_stretches(tmp_path, monkeypatch):
    _, events = live_run(tmp_path / "live", "sim://?faults=wrong-crc")
    path = str(tmp_path / "run.sr")
    export_events(events, path, "sr", tool_channel=True)
    whole, _, _ = _decoded(path, monkeypatch, 16)
    one, _, _ = _decoded(path, monkeypatch, 10**9)
    _same(whole, one)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.floats(0, 2.0), min_size=1, max_size=40),
    st.lists(st.tuples(st.floats(0, 2.0), st.integers(0, 1), st.booleans()), max_size=40),
    st.sampled_from([0.0004, 0.01, 0.1]),
    st.integers(0, 5),
)
def test_the_search_gives_the_walks_origins(bus, tx, tol, j0):
    starts = sorted(bus)
    wires = [int(s * 1000) % 2 for s in starts]
    tx = sorted(tx)
    marks = Marks(tolerance=tol)
    for t, w, is_char in tx:
        marks.add(EventKind.CHAR if is_char else EventKind.BREAK, t, w)
    j0 = min(j0, len(tx))
    b = Batch(
        [], starts, starts, wires, [], [], [], [],
        start_array=np.array(starts), wire_array=np.array(wires, dtype=np.int64),
    )  # fmt: skip
    found = _origins(_TxArrays.of(marks), b, 0, len(starts), j0, tol, "dut")
    marks.at = j0
    walked = [marks.origin(EventKind.CHAR, s, w, "dut") for s, w in zip(starts, wires, strict=True)]
    if found is not None:
        origins, at, hits = found
        assert origins == walked
        assert (at, hits) == (marks.at, marks.matched)
