"""Reading a sigrok session: a probe's edges found among the words that change (any probe)
are the ones its own levels give (``edges.transitions``, the general reader)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture import sigrok
from conformance.capture.edges import transitions
from conformance.capture.writers import Channel, write_sr


@settings(max_examples=300, deadline=None)
@given(
    st.sampled_from([np.uint8, np.dtype("<u2"), np.dtype("<u4"), np.dtype("<u8")]),
    st.lists(st.integers(0, 2**64 - 1), min_size=1, max_size=60),
    st.integers(0, 63),
    st.sampled_from([None, 0, 1]),
    st.integers(0, 10**9),
)
def test_a_probes_transitions_are_its_levels_transitions(dtype, words, bit, previous, offset):
    block = np.array(words, dtype=np.uint64).astype(dtype)
    bit = bit % (8 * block.itemsize)
    levels = (block >> bit) & 1
    want, last = transitions(levels, previous)
    assert sigrok._transitions(block, bit, previous, offset) == (
        [offset + i for i in want],
        last,
    )


@settings(max_examples=200, deadline=None)
@given(
    st.sampled_from([np.uint8, np.dtype("<u2"), np.dtype("<u4"), np.dtype("<u8")]),
    st.lists(st.integers(0, 2**64 - 1), min_size=1, max_size=60),
    st.lists(st.integers(0, 63), min_size=1, max_size=8, unique=True),
)
def test_each_probes_changes_are_counted_as_its_levels_change(dtype, words, bits):
    """``probe_changes`` (which picks the busiest probe of a session) counts what a pass over
    each probe's own levels counts."""
    block = np.array(words, dtype=np.uint64).astype(dtype)
    probes = {f"D{b}": b % (8 * block.itemsize) for b in bits}
    assert sigrok.probe_changes(block, probes) == {
        name: int(np.count_nonzero(np.diff((block >> bit) & 1))) for name, bit in probes.items()
    }


@pytest.mark.parametrize("block", [997, 1 << 22])
def test_a_session_reads_as_its_levels_say(tmp_path, monkeypatch, block):
    """Three probes over many blocks (edges on the blocks' bounds too), one idle low."""
    monkeypatch.setattr(sigrok, "BLOCK_SAMPLES", block)
    rng = np.random.default_rng(5)
    total = 60_000
    probes = {
        "A": sorted({*rng.integers(0, total, 400).tolist()}),
        "B": sorted({*range(0, total, 997), *range(1, total, 997), 996, 59_999}),
        "C": [],
    }
    path = str(tmp_path / "three.sr")
    idle = {"A": 1, "B": 0, "C": 1}
    write_sr(path, [Channel(n, idle[n], e) for n, e in probes.items()], 1e5, total)
    for name, edges in probes.items():
        got = sigrok.read_sr(path, name)
        assert got.initial_level == (idle[name] ^ (0 in edges))
        assert [t for chunk in got.chunks for t in chunk] == [t for t in edges if t > 0]
        assert got.end() == total


def _three_probes(tmp_path, monkeypatch) -> tuple[str, dict[str, list[int]]]:
    monkeypatch.setattr(sigrok, "BLOCK_SAMPLES", 997)
    rng = np.random.default_rng(7)
    total = 30_000
    probes = {
        "A": sorted({*rng.integers(0, total, 300).tolist()}),
        "B": sorted({0, *rng.integers(0, total, 200).tolist(), total - 1}),
        "C": [],
    }
    path = str(tmp_path / "three.sr")
    write_sr(path, [Channel(n, 1, e) for n, e in probes.items()], 1e5, total)
    return path, probes


def _read_all(path: str, channel: str) -> tuple:
    got = sigrok.read_sr(path, channel)
    edges = [t for chunk in got.chunks for t in chunk]
    return got.initial_level, edges, got.end(), got.notes, got.channels, got.channel


def test_a_probe_kept_from_another_probes_pass_reads_as_its_own_pass(tmp_path, monkeypatch):
    """judge reads the bus channel, then the TX channel: the second read takes the edges
    the first pass kept, without a pass of its own, and they are that pass's exactly."""
    path, probes = _three_probes(tmp_path, monkeypatch)
    fresh = {}
    for name in probes:
        sigrok._OTHERS.clear()
        fresh[name] = _read_all(path, name)
    for first in probes:
        sigrok._OTHERS.clear()
        _read_all(path, first)
        with monkeypatch.context() as m:  # no second pass over the samples
            m.setattr(sigrok.SrSession, "blocks", lambda self: pytest.fail("read again"))
            for name in probes:
                if name != first:
                    assert _read_all(path, name) == fresh[name]
    assert fresh["B"][1] == [t for t in probes["B"] if t > 0]


def test_a_long_pass_keeps_no_other_probe(tmp_path, monkeypatch):
    path, probes = _three_probes(tmp_path, monkeypatch)
    sigrok._OTHERS.clear()
    fresh = _read_all(path, "B")
    monkeypatch.setattr(sigrok, "OTHERS_MAX_EDGES", 100)  # A's 300 edges are too many
    sigrok._OTHERS.clear()
    _read_all(path, "A")
    assert not sigrok._OTHERS
    assert _read_all(path, "B") == fresh
    # a file written again is read again, not taken from what its former self kept
    monkeypatch.setattr(sigrok, "OTHERS_MAX_EDGES", 1 << 20)
    _read_all(path, "A")
    assert sigrok._OTHERS
    write_sr(path, [Channel("A", 1, probes["A"]), Channel("B", 1, [5, 9])], 1e5, 30_001)
    assert _read_all(path, "B")[1] == [5, 9]
