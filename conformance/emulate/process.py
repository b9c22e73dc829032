"""``sdi12-conform emulate`` in a child process, for tests and benchmarks.

A separate process keeps the emulator's real-time line off the judging process's GIL, as it
would be on a bench (the sensor is another machine). The child prints the URL it serves on;
``port 0`` lets the OS pick a free loopback port, so parallel runs never collide.
"""

from __future__ import annotations

import subprocess
import sys


class EmulatorProcess:
    """The reference sensor served over RFC 2217 on 127.0.0.1; ``url`` is where."""

    def __init__(self, *extra: str, start_timeout: float = 20.0) -> None:
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

    def stop(self) -> None:
        """SIGTERM (the server stops accepting and exits), then kill if it hangs."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        if self.proc.stdout:
            self.proc.stdout.close()

    def __enter__(self) -> EmulatorProcess:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.stop()
