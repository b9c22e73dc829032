"""A decoded capture gives the C heap's freed pages back (``capture/heap.py``, issue 22): the
decoder's transients left 11 MB resident in some runs and not in others, so the same
judgement of a busy 14-minute capture peaked at 80.6 or 87.8 MB by chance, and
``tests/offline/test_judge_memory.py``'s slope with it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import conformance.capture.decode as capture_decode
from conformance.capture import decode_capture
from conformance.capture.heap import give_back_freed_heap
from tests.offline.test_judge_memory import busy_capture

#: in a child process of its own (the test's heap is its alone): 40 MB of 64 KB blocks
#: (below glibc's mmap threshold: carved from the heap), small blocks after them keep the
#: heap's top in use, then the big ones are freed: resident until trimmed (51 MB against 11
#: before them; 11 once trimmed)
PINNED = """
import sys
from conformance.capture.heap import give_back_freed_heap

def rss_mb():
    with open("/proc/self/status") as status:
        return next(int(l.split()[1]) for l in status if l.startswith("VmRSS:")) / 1024

blocks = [bytearray(65536) for _ in range(640)]
pins = [bytearray(2048) for _ in range(64)]
del blocks
before = rss_mb()
if not give_back_freed_heap():
    print("no-trim")
    sys.exit(0)
print(before - rss_mb())
"""


def test_freed_heap_pages_are_given_back():
    if not Path("/proc/self/status").exists():
        pytest.skip("no /proc: resident memory is read from /proc/self/status")
    done = subprocess.run(
        [sys.executable, "-c", PINNED], capture_output=True, text=True, check=True,
        env={"MALLOC_ARENA_MAX": "1", "PYTHONPATH": str(Path(__file__).parents[2])},
    )  # fmt: skip
    out = done.stdout.strip()
    if out == "no-trim":
        pytest.skip("this C library has no malloc_trim")
    assert float(out) >= 30, f"only {out} MB of the 40 MB freed given back"


def test_a_decode_gives_back_what_its_transients_freed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    monkeypatch.setattr(capture_decode, "_LAST", None)
    calls: list[bool] = []
    monkeypatch.setattr(capture_decode, "give_back_freed_heap", lambda: calls.append(True))
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.05)
    decoded = decode_capture(str(path), keep=False)
    assert decoded.chars and calls == [True]
    decode_capture(str(path), keep=False)  # decoded again (nothing kept): trimmed again
    assert calls == [True, True]


def test_trimming_leaves_what_python_holds():
    held = [bytes([i]) * 70_000 for i in range(50)]
    give_back_freed_heap()
    assert all(b == bytes([i]) * 70_000 for i, b in enumerate(held))
