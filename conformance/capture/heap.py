"""Giving the C heap's freed pages back to the system once a capture is decoded.

The decoder's transients (numpy arrays, the read-ahead thread's inflated chunks) come and go
through glibc's malloc, whose mmap threshold rises each time a large mapped block is freed:
later large blocks are then carved from the heap, and when they are freed the heap keeps
their pages resident unless its top is free. Whether it is depends on which small block the
two threads happened to leave last, so a judgement of the same busy 14-minute capture
peaked at 80.6 MB in most runs and 87.8 in others (the decode's 11 MB left resident: RSS
66 MB after it, where the others had 55), and ``tests/offline/test_judge_memory.py``'s
slope read 1.57 or 2.2 MB a minute of capture by chance. ``malloc_trim(0)`` returns every
free page of the heap, wherever it is: 51 MB after the decode, every run.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from functools import cache


@cache
def _malloc_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, or None where the C library has none (macOS, musl) or the
    process's own symbols cannot be opened (Windows). Looked up among the symbols the
    process has loaded, not by ``ctypes.util.find_library``, which runs ``ldconfig`` (23 ms)."""
    try:
        return ctypes.CDLL(None).malloc_trim  # type: ignore[no-any-return]
    except (OSError, AttributeError, TypeError):
        return None


def give_back_freed_heap() -> bool:
    """Return the heap's free pages to the system (True), or do nothing where the C library
    cannot (False). What Python holds is untouched: only pages malloc already counts free."""
    trim = _malloc_trim()
    if trim is None:
        return False
    trim(0)
    return True
