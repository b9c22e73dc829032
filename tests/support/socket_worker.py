"""A rack worker host on this machine: execnet's own socket server on loopback, so a test
can name a worker that is not a local ``popen`` one (``--tx socket=127.0.0.1:PORT``) and
go through what a worker on another host does: the declaration sent over, the report
folder's files sent back, the stop passed on over the channel."""

from __future__ import annotations

import re
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import execnet


@contextmanager
def socket_worker_host() -> Iterator[str]:
    """Serve execnet's socket server on a free loopback port; yield its ``--tx`` spec."""
    script = Path(execnet.__file__).parent / "script" / "socketserver.py"
    proc = subprocess.Popen(
        [sys.executable, "-u", str(script), "127.0.0.1:0"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    try:
        line = proc.stdout.readline() if proc.stdout else ""
        found = re.search(r"'127\.0\.0\.1', (\d+)\)", line)
        if not found:
            raise RuntimeError(f"execnet's socket server did not start: {line!r}")
        yield f"socket=127.0.0.1:{found[1]}"
    finally:
        proc.kill()
        proc.wait(timeout=10)
