"""The bulk decoder's third pass taking a run of certified frames in one step (issue 22,
matrix22: ``uart_bulk._run_ends``) against the same pass stepping frame by frame (every run
one frame long): the same batches, field for field, over hypothesis streams (off-rate
senders, framing errors, glitches, breaks, noise, small windows carrying frames across) and
an exported busy run, where runs are indeed taken. The reference decoder's own comparison
(``test_uart_bulk.py``) holds too; this one pins the batches, markings included."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conformance.capture import uart_bulk
from conformance.capture.export import export_events
from conformance.capture.formats import read_edges
from tests.capture.test_uart_bulk import busy_run, streams


def _one_by_one(starts, position, ok, nxt, settled):
    return list(range(starts.size))


def _batches(chunks, kw, window=None) -> list[tuple]:
    got = []
    for b in uart_bulk.decode_batches([list(c) for c in chunks], window=window, **kw):
        p = range(len(b.start))
        got.append(
            (
                b.order, b.start, b.end, b.wire, b.framing_error, b.parity_error,
                [x if x == x else "nan" for x in b.err_nan], b.glitches, b.start_ticks,
                b.before, [b.marking(i) for i in p], b.flagged,
            )
        )  # fmt: skip
    return got


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(streams(), st.sampled_from([None, 4, 9, 33]))
def test_runs_taken_whole_give_the_frame_by_frame_batches(found, window):
    chunks, kw = found
    whole = _batches(chunks, kw, window)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(uart_bulk, "_run_ends", _one_by_one)
        assert _batches(chunks, kw, window) == whole


@pytest.mark.parametrize("slow", [1.0, 1.03])
def test_an_exported_runs_batches_are_the_same_and_runs_are_taken(tmp_path, monkeypatch, slow):
    """A busy exported run (replies at and off the nominal rate): the same batches both
    ways, and at the nominal rate most certified frames are reached inside a run."""
    path = tmp_path / "run.vcd"
    export_events(busy_run(slow), str(path))
    edges = read_edges(str(path), None, "vcd")
    chunks = [list(c) for c in edges.chunks]
    kw = dict(initial_level=edges.initial_level, tick_rate=edges.tick_rate, t0=edges.t0)
    ends: list[list[int]] = []
    real = uart_bulk._run_ends

    def counted(*args):
        ends.append(real(*args))
        return ends[-1]

    monkeypatch.setattr(uart_bulk, "_run_ends", counted)
    whole = _batches(chunks, kw)
    inside = sum(q > p for e in ends for p, q in enumerate(e))
    frames = sum(len(e) for e in ends)
    if slow == 1.0:
        assert frames > 1000 and inside > frames // 2
    monkeypatch.setattr(uart_bulk, "_run_ends", _one_by_one)
    assert _batches(chunks, kw) == whole
