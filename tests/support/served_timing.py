"""The one rule the tests of a served (real-time) line share for a wrong result: fail on it,
unless the served line itself could not keep real time, in which case its timing is no
evidence either way and the test skips with the figure (tests/conftest.py lists such skips
under "skipped because the machine was busy")."""

from __future__ import annotations

import pytest

from conformance.emulator_server.realtime import LATE_NOTICE


def fail_unless_too_busy(late: float | None, wrong: str, text: str) -> None:
    """``wrong``: what the run got wrong ("" for nothing); ``late``: how far (s) the served
    line fell behind its schedule (None: the emulator did not say); ``text``: the run's
    output, shown with a failure."""
    if not wrong:
        return
    if late is not None and late > LATE_NOTICE:
        pytest.skip(
            f"the machine was too busy to keep real time: the served line fell "
            f"{late * 1e3:.1f} ms behind its schedule; {wrong}"
        )
    pytest.fail(f"{wrong} (line late by {late} s):\n{text}")
