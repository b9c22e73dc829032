"""How late this host wakes a sleeping thread, measured while a real-time test runs.

A process the tests start (an external recorder, a harness) is timed by the host's scheduler,
not by a served line that reports its own lateness. When such a process misses a protocol
window, the figure that tells a busy machine from a wrong program is how late the host woke
threads meanwhile: a probe thread here asks for short sleeps and keeps the worst overshoot.
"""

from __future__ import annotations

import threading
import time
from types import TracebackType

#: s: the probe's sleep; short, like the waits of a recorder between command and retry
NAP = 0.005


class HostLag:
    """``with HostLag() as lag: ...`` then ``lag.worst`` (s): the worst time a ``NAP`` sleep
    overran while the block ran."""

    def __init__(self) -> None:
        self.worst = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._probe, name="host-lag", daemon=True)

    def _probe(self) -> None:
        while not self._stop.is_set():
            asked = time.perf_counter()
            time.sleep(NAP)
            self.worst = max(self.worst, time.perf_counter() - asked - NAP)

    def __enter__(self) -> HostLag:
        self._thread.start()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self._stop.set()
        self._thread.join()
