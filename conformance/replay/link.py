"""``--port replay:PATH``: open a saved run's recording as the device under test."""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from ..links.base import LinkInfo
from ..sim.bus import SimBus, SimLink
from .recording import Recording, RecordingError, read_recording
from .sensor import RecordedSensor

SCHEME = "replay:"

#: Link kinds whose runs replay exactly: their clock is virtual, so the tool's stimuli come at
#: the recorded times and the recorded answers meet them as they did.
VIRTUAL_KINDS = ("sim", "exec", "unix")


def is_replay(port: str) -> bool:
    return port.startswith(SCHEME)


def replay_path(port: str) -> str:
    path = port[len(SCHEME) :]
    if path.startswith("//"):
        path = path[2:]
    if not path:
        raise RecordingError(f"port {port!r}: write replay:PATH (a run folder or transcript.jsonl)")
    return path


def recorded_info(recording: Recording) -> LinkInfo:
    """The recorded run's link as the cases must see it again (a harness link stays without
    bit timing: the replay must not judge frames the tool made)."""
    saved: dict[str, Any] = dict(recording.options.get("link") or {})
    known = {f.name for f in fields(LinkInfo)}
    info = LinkInfo(**{k: v for k, v in saved.items() if k in known}) if saved else None
    if info is None:
        kind = (recording.verdicts or {}).get("run", {}).get("link", {}).get("kind", "sim")
        info = LinkInfo(kind=kind, virtual_time=True)
    kind = info.kind.removeprefix("replay of ")
    if not info.virtual_time or kind not in VIRTUAL_KINDS:
        raise RecordingError(
            f"{recording.path}: a run over a {info.kind} link (real time) cannot be replayed "
            "exactly; judge it passively (sdi12-conform judge FILE judges what is on the wire)"
        )
    return info


def replayed_info(recording: Recording) -> LinkInfo:
    """The link info a replay reports: the recorded one's capabilities, named a replay."""
    base = recorded_info(recording)
    held = recording.held.largest_uncertainty() if recording.held is not None else None
    stamped = (
        held if held is not None else max((e.uncertainty for e in recording.events), default=0.0)
    )
    return LinkInfo(
        kind="replay of " + base.kind.removeprefix("replay of "),
        can_break=base.can_break,
        passes_unsolicited=base.passes_unsolicited,
        binary=base.binary,
        # a decoded capture's events carry its sample-period uncertainty: judged with it
        timing_uncertainty=max(base.timing_uncertainty, stamped),
        virtual_time=True,
        bit_timing=base.bit_timing,
        frame_lengths=base.frame_lengths,  # the replay plays each frame at its own length
    )


class ReplayLink(SimLink):
    """The tool's end of a simulated bus whose one device is the recording."""

    def __init__(self, recording: Recording, device: object) -> None:
        super().__init__(SimBus([device]))  # type: ignore[list-item]
        self.info = replayed_info(recording)
        self.recording = recording


def open_sensor_replay(port: str) -> tuple[ReplayLink, Recording]:
    recording = read_recording(replay_path(port))
    return ReplayLink(recording, recorded_sensor(recording)), recording


def recorded_sensor(recording: Recording) -> RecordedSensor:
    """The recording's sensor: a decoded capture held as columns gives it its columns (no
    reply character made an event, issue 22), anything else its events."""
    if recording.held is not None:
        sensor = RecordedSensor.of_columns(recording.held.wire)
        if sensor is not None:
            return sensor
    return RecordedSensor(recording.events)


def open_recorder_replay(port: str) -> Recording:
    """The recording behind a recorder-role ``replay:PATH`` (checked replayable)."""
    recording = read_recording(replay_path(port))
    recorded_info(recording)
    return recording
