"""The ``recorder`` session fixture of the pytest plugin (recorder-role cases use it)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from ..exits import EXIT_USAGE
from ..ports import PortError

if TYPE_CHECKING:  # the run makes the session (ConformanceRun.recorder_session), importing
    # the runner then: a sensor-role run never loads the recorder role's modules
    from .scenario_runner import RecorderSession


@pytest.fixture(scope="session")
def recorder(sdi12_run) -> RecorderSession:  # noqa: ANN001 - the plugin's ConformanceRun
    """The recorder under test (recorder role): the scenario runner, created once per run."""
    if sdi12_run.options.role != "recorder":
        pytest.skip("recorder-role case; this run judges a sensor")
    try:
        return sdi12_run.recorder_session()
    except PortError as exc:
        sdi12_run.cut_short(str(exc), EXIT_USAGE)
