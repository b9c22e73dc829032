"""Back-to-back characters share a stamp (issue 22, bounded memory): the bulk decoder gives
a frame whose start equals the end before it that end's own float object, not a second
one (24 bytes an event, most of a busy bus's), and the events are still the reference
decoder's, value for value."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from conformance.capture import uart_bulk
from tests.capture.test_uart_bulk import both_ways, same_decode
from tests.offline.test_judge_memory import busy_capture


def test_equal_stamps_are_one_object_and_the_values_stay():
    starts = np.array([0.0, 1.0, 2.0, 3.5, 4.5])
    ends = np.array([1.0, 2.0, 3.0, 4.5, 5.0])
    first, last = uart_bulk._stamps(starts, ends)
    assert first == starts.tolist() and last == ends.tolist()
    assert first[1] is last[0] and first[2] is last[1] and first[4] is last[3]
    assert first[3] is not last[2]  # 3.5 after 3.0: a gap, its own stamp
    zero = uart_bulk._stamps(np.array([-1.0, -0.0]), np.array([0.0, 1.0]))[0][1]
    assert str(zero) == "-0.0"  # a zero keeps its own sign


def test_a_busy_capture_shares_its_stamps_and_reads_as_the_reference(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.05)
    bulk, reference = both_ways(monkeypatch, path)
    same_decode(bulk, reference)
    events = bulk.events
    equal = [(a, b) for a, b in zip(events, events[1:], strict=False) if a.end == b.start]
    shared = sum(1 for a, b in equal if a.end is b.start)
    assert len(equal) > len(events) / 2 and shared >= 0.95 * len(equal)
