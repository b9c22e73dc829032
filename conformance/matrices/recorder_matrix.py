"""The recorder fault-detection matrix: every faulty golden recorder against the whole
recorder suite, compared with the requirements the fault declares (design.md 5)."""

from __future__ import annotations

from typing import Any

from ..conduct import run_once


def run_recorder_suite(port: str = "sim", **options: Any) -> dict:
    """Run the recorder suite in this process against ``port``; return verdicts.json.
    ``options``: more RunOptions fields (``version="1.3"``)."""
    return run_once(port, role="recorder", **options)
