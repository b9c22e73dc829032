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
