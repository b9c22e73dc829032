"""Fixtures of the passive judgement's tests."""

from __future__ import annotations

from pathlib import Path

import pytest

import conformance.capture.decode as capture_decode
from tests.offline.test_judge_memory import busy_capture


@pytest.fixture
def capture(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Three seconds of a busy bus (ten sensors, ``capture_decode.busy_bus``) as a 1 MHz
    sigrok session, decoded afresh (no decode kept from another test)."""
    monkeypatch.setattr(capture_decode, "_LAST", None)
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.05)
    return path
