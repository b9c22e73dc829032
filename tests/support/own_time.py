"""How long a block took on this thread, less the time it stood waiting for a CPU.

A test that proves work runs in virtual time ("ttt 999 completes in well under a second")
used to hold the wall time to a bound. Beside busy processes (CI runs these tests at nice 19
next to the real-time session at nice 0) a thread that needs 0.2 s of CPU can stand in the
run queue for 15 s or more, and the bound failed with nothing wrong (tests/recorder/
test_sweep.py's full sweep: 14 and 22 s of wall time for 0.2 s of CPU). What the bound is
there for shows in the two other parts of the wall time, which no load changes: the time the
thread ran (work) and the time it was blocked (a real sleep or wait: a simulated wait that
became a real one). The kernel counts both for each thread (``/proc/thread-self/schedstat``:
time on a CPU, time runnable in a run queue), so ``wall - runnable`` is the wall time the
block would take on an idle machine.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

SCHEDSTAT = Path("/proc/thread-self/schedstat")


def runnable(schedstat: Path = SCHEDSTAT) -> float:
    """Seconds a thread has spent runnable but not running (0 where the kernel does not
    say: the wall time is then the figure, as before): this thread's by default, or another
    task's given its ``/proc/PID/schedstat`` (a child process's main thread)."""
    try:
        _on_cpu, waiting, _slices = schedstat.read_text().split()
    except (OSError, ValueError):
        return 0.0
    return int(waiting) / 1e9


@dataclass
class OwnTime:
    """Filled in when the ``with`` block ends."""

    wall: float = 0.0
    #: s the thread stood in a run queue: the machine's load, not the code's
    queued: float = 0.0

    @property
    def seconds(self) -> float:
        """The wall time less the queueing: running and blocked (sleeping, waiting)."""
        return self.wall - self.queued


@contextmanager
def own_time() -> Iterator[OwnTime]:
    """``with own_time() as t: ...`` then ``t.seconds``: the block's wall time on this
    thread with the time it waited for a CPU taken out. Work handed to other threads or
    processes counts as this thread's waiting for it (blocked), theirs queueing included:
    use it where the code under test runs on the calling thread."""
    took = OwnTime()
    wall, queued = time.perf_counter(), runnable()
    try:
        yield took
    finally:
        took.wall = time.perf_counter() - wall
        took.queued = runnable() - queued
