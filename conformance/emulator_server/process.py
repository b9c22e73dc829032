"""``sdi12-conform emulate`` in a child process, for tests and benchmarks.

A separate process keeps the emulator's real-time line off the judging process's GIL, as it
would be on a bench (the sensor is another machine). The child prints the URL it serves on;
``port 0`` lets the OS pick a free loopback port, so parallel runs never collide.
"""

from __future__ import annotations

import re
import subprocess
import sys
import threading
import time


class EmulatorProcess:
    """The reference sensor served over RFC 2217 on 127.0.0.1; ``url`` is where."""

    def __init__(self, *extra: str) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "conformance.cli", "emulate", "--listen", "127.0.0.1:0", *extra],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        line = self.proc.stdout.readline() if self.proc.stdout else ""
        self.url = next((w for w in line.split() if w.startswith("rfc2217://")), "")
        if not self.url:
            self.stop()
            raise RuntimeError(f"the emulator did not start: {line.strip()!r}")
        self.log: list[str] = [line.strip()]
        self._reader = threading.Thread(target=self._collect, daemon=True)
        self._reader.start()

    def _collect(self) -> None:
        for line in self.proc.stdout or ():
            self.log.append(line.strip())

    def worst_lateness(self, connections: int | None = 2, wait: float = 3.0) -> float | None:
        """How far (s) the served line fell behind its schedule, the worst over the log lines
        the server writes when a recorder disconnects, once ``connections`` of them are in
        (the CLI connects twice: a port check, then the run; None: as many as have connected
        so far, for a run whose count varies, such as a bus run's one per sensor). None if
        they did not come."""
        deadline = time.monotonic() + wait
        if connections is None:
            connections = sum(line.startswith("recorder connected") for line in list(self.log))
        while True:
            found = [re.search(r"within ([0-9.]+) ms", line) for line in list(self.log)]
            values = [float(m[1]) / 1e3 for m in found if m]
            if len(values) >= connections:
                return max(values)
            if time.monotonic() >= deadline:
                return max(values) if values else None
            time.sleep(0.05)

    def stop(self) -> None:
        """SIGTERM (the server stops accepting and exits), then kill if it hangs."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        if self._reader_started():
            self._reader.join(timeout=2)

    def _reader_started(self) -> bool:
        return hasattr(self, "_reader")

    def __enter__(self) -> EmulatorProcess:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.stop()
