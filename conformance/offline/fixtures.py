"""The passive cases' session fixtures: ``heard_sensors`` (the sensor rules) and
``heard_recorder`` (the recorder rules), both over the run's ``recording:`` port.

The plugin maps a case to its role by the fixture it asks for (``plugin.case_role``), so a
passive run with ``--sdi12-role sensor`` keeps the sensor-rule cases and aggregates them as
role ``sensor``, and likewise for the recorder. The recording is loaded once per process
(``--role both`` runs the suite twice in one process and decodes a capture once).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from ..exits import EXIT_USAGE
from ..links.errors import PortError
from ..run import ConformanceRun

if TYPE_CHECKING:  # imported by a passive run only: the plugin loads this module for every run
    from ..replay.recording_link import RecordingLink
    from .heard import HeardRecorder, HeardSensors

_LOADED: dict[str, RecordingLink] = {}


def recording_of(port: str) -> RecordingLink:
    """The recording a ``recording:`` port names, loaded once (PortError if it cannot be)."""
    from ..replay.recording_link import load_recording, parse_recording

    if port not in _LOADED:
        _LOADED[port] = load_recording(parse_recording(port))
    return _LOADED[port]


def _heard(run: ConformanceRun, role: str):
    from ..replay.recording_link import is_recording

    if run.options.role != role:
        pytest.skip(f"{role}-rule case; this run judges the {run.options.role} rules")
    if not is_recording(run.options.port):
        pytest.skip("a passive case judges a recording: --sdi12-port recording:PATH")
    if run.session is None:
        from .heard import hear_recorder, hear_sensors

        try:
            link = recording_of(run.options.port)
        except PortError as exc:
            run.cut_short(str(exc), EXIT_USAGE)
        run.link = link  # a recording: a bus end the tool does not transmit on
        if role == "sensor":
            run.session = hear_sensors(link, run.options.address, run.options.version)
        else:
            run.session = hear_recorder(link, run.options.version)
    return run.session


@pytest.fixture(scope="session")
def heard_sensors(sdi12_run: ConformanceRun) -> HeardSensors:
    """What the sensors sent in the recording, as the tool recorder's records."""
    return _heard(sdi12_run, "sensor")


@pytest.fixture(scope="session")
def heard_recorder(sdi12_run: ConformanceRun) -> HeardRecorder:
    """What the recorder sent in the recording, as the role-neutral view."""
    return _heard(sdi12_run, "recorder")
