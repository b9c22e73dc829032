"""Where the tests find the checkout and the shared ground truth, from any folder depth."""

from __future__ import annotations

from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]  # tests/
ROOT = TESTS.parent  # the checkout
SHARED = ROOT.parent / "shared"  # ../shared: the spec texts, requirements.md, captures
