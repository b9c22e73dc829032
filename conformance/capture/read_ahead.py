"""A capture's edge chunks read ahead by a thread while the decoder reads the ones before.

An hour of a 1 MHz sigrok session is 3.6 GB of samples to inflate, check (the zip member's
CRC) and scan for transitions: about two fifths of a decode's CPU, all of it in zlib and
numpy, which let go of the interpreter lock while they work. The UART decoder's loop is
Python. So on a machine with a second core the reading costs the decode almost no wall time
when a thread does it a few blocks ahead: what the decoder gets is the same chunks in the
same order, and at most ``depth`` chunks wait (memory stays bounded whatever the length).
A failure of the reader (a damaged member) is raised in the decoder, where it would have
been raised without the thread.
"""

from __future__ import annotations

import queue
import threading
import weakref
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import TypeVar

T = TypeVar("T")

DEPTH = 3  # chunks read ahead: enough to keep the thread busy, a few MB of edges at most
POLL_S = 0.1  # how often a reader held up by a full queue looks whether it was abandoned


@dataclass(frozen=True)
class _Failed:
    error: BaseException


_END = object()


def read_ahead(chunks: Iterable[T], depth: int = DEPTH) -> Iterator[T]:
    """``chunks``, produced by a daemon thread up to ``depth`` ahead of the caller. Closing
    the returned iterator early (or dropping it) lets the thread end at its next chunk."""
    ready: queue.Queue[object] = queue.Queue(maxsize=depth)
    abandoned = threading.Event()

    def put(item: object) -> bool:
        while not abandoned.is_set():
            try:
                ready.put(item, timeout=POLL_S)
                return True
            except queue.Full:
                continue
        return False

    def work() -> None:
        try:
            for chunk in chunks:
                if not put(chunk):
                    return
        except BaseException as exc:  # handed to the caller, raised there
            put(_Failed(exc))
            return
        put(_END)

    threading.Thread(target=work, name="capture-read-ahead", daemon=True).start()
    taken = _taken(ready, abandoned)
    weakref.finalize(taken, abandoned.set)  # dropped before its first chunk: stop too
    return taken


def _taken(ready: queue.Queue[object], abandoned: threading.Event) -> Iterator[T]:
    try:
        while True:
            item = ready.get()
            if item is _END:
                return
            if isinstance(item, _Failed):
                raise item.error
            yield item  # type: ignore[misc]
    finally:
        abandoned.set()
