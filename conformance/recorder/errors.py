"""The ways making the recorder under test act can fail (kept apart from the drivers so
that :mod:`.job_time` and the drivers can both raise them)."""

from __future__ import annotations


class RecorderDriverError(RuntimeError):
    """The recorder could not be made to act (trigger failed, timed out, no operator)."""


class RecorderSetupError(RecorderDriverError):
    """The driver failed and the recorder never spoke: the test setup is broken (a trigger
    that cannot start, or exits non-zero before making the recorder act), not the recorder.
    Judging the silent line would blame the recorder for the tool's setup (false FAILs)."""
