"""The recorder fault-detection matrix: every faulty golden recorder against the whole
recorder suite, compared with the requirements the fault declares (design.md 5)."""

from __future__ import annotations

from ..matrix import run_once


def run_recorder_suite(port: str = "sim", extra: tuple[str, ...] = ()) -> dict:
    """Run the recorder suite in this process against ``port``; return verdicts.json."""
    return run_once(port, extra, role="recorder")
