"""The read-ahead thread of a capture's edge chunks (conformance/capture/read_ahead.py): the
same chunks in the same order, a reader's failure raised in the caller, at most ``depth``
chunks waiting, and a thread that ends once the caller stops reading."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest

from conformance.capture.errors import CaptureError
from conformance.capture.read_ahead import read_ahead


def _threads() -> int:
    return sum(t.name == "capture-read-ahead" for t in threading.enumerate())


def _settle(until: int, timeout: float = 5.0) -> int:
    end = time.monotonic() + timeout
    while _threads() > until and time.monotonic() < end:
        time.sleep(0.02)
    return _threads()


def test_same_chunks_in_order() -> None:
    chunks = [[i, i + 1, i + 2] for i in range(0, 3000, 3)]
    assert list(read_ahead(iter(chunks))) == chunks
    assert list(read_ahead(iter([]))) == []


def test_failure_raised_in_the_caller_after_the_chunks_before_it() -> None:
    def broken() -> Iterator[list[int]]:
        yield [1, 2]
        yield [3]
        raise CaptureError("x.sr", "corrupt sample data")

    got: list[list[int]] = []
    with pytest.raises(CaptureError, match="corrupt sample data"):
        for chunk in read_ahead(broken()):
            got.append(chunk)
    assert got == [[1, 2], [3]]


def test_reads_at_most_depth_ahead() -> None:
    produced: list[int] = []

    def counted() -> Iterator[list[int]]:
        for i in range(100):
            produced.append(i)
            yield [i]

    ahead = read_ahead(counted(), depth=2)
    assert next(ahead) == [0]
    time.sleep(0.3)  # the thread has had time to fill the queue
    # one handed out, two queued, one more produced and waiting to be queued
    assert len(produced) <= 4
    ahead.close()


def test_thread_ends_when_the_caller_stops() -> None:
    before = _threads()

    def endless() -> Iterator[list[int]]:
        i = 0
        while True:
            yield [i]
            i += 1

    ahead = read_ahead(endless())
    assert next(ahead) == [0]
    ahead.close()
    never_read = read_ahead(endless())
    del never_read  # dropped before its first chunk
    # at most as many as before: a thread an earlier test in this worker left may end meanwhile
    assert _settle(before) <= before
