"""A recording of a bus of several sensors, as a monitor or a capture of it would give it.

Clean (or faulty) emulators sit on one :class:`~conformance.sim.bus.SimBus`; the tool
recorder engine identifies each, starts a concurrent measurement on every one in turn
(interleaved, as concurrent measurement is meant to be used), waits the longest ttt out and
then reads each sensor's data with a break in front. The transcript is written with origin
``bus`` on every event (what a one-wire capture or a listen-only monitor holds), so the
view infers every direction itself and ``judge`` judges it passively.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path

from conformance.emulator.profile import default_profile
from conformance.emulator.sensor import SensorEmulator
from conformance.replay.recording import write_recording
from conformance.sensor.bus_round import start_measurement
from conformance.sim.bus import SimBus, SimLink
from conformance.tool_recorder import ToolRecorder
from conformance.tool_recorder.records import Measurement
from conformance.transcript import BUS, Event, EventKind

ADDRESSES = "013"


def serial(address: str) -> str:
    """The serial number (optional identification field) the sensor at ``address`` gives."""
    return f"SN000{address}"


def bus_of_sensors(
    addresses: str = ADDRESSES, faults: Mapping[str, Sequence[str]] | None = None
) -> tuple[SimBus, ToolRecorder]:
    """A bus with one default-profile emulator per address (``faults``: per address), each
    with its own serial number so that the identifications differ."""
    bus = SimBus()
    for a in addresses:
        profile = replace(default_profile(), address=a, optional=serial(a))
        bus.attach(SensorEmulator(profile, (faults or {}).get(a, ()), name=f"sensor-{a}"))
    return bus, ToolRecorder(SimLink(bus))


def start(recorder: ToolRecorder, text: str) -> Measurement:
    """A measurement started (its reply recorded), its data not yet asked for."""
    m = start_measurement(recorder, text)
    assert m.count is not None, m.start.reply_text
    return m


def measured_past_another(
    recorder: ToolRecorder, text: str = "0M!", other: str = "1I!"
) -> Measurement:
    """``text`` started, ``other`` (a command to another sensor) sent before its service
    request, then its data asked for after the ttt with a break (R-4.4.5-06's disturbance:
    on the wire the D command follows, for a rebuild to take wrongly)."""
    m = start(recorder, text)
    recorder.transact(other)
    recorder.link.wait_until(recorder.link.now() + m.ttt + 0.1)
    recorder.collect(m, force_break=True)
    return m


def concurrent_round(
    recorder: ToolRecorder,
    addresses: str = ADDRESSES,
    *,
    code: str = "C",
    meddle: Mapping[str, str] | None = None,
) -> list[Measurement]:
    """``a<code>!`` to each sensor in turn, then (ttt out) the D commands of each, a break
    before each sensor's first. ``meddle``: address -> a command sent to that sensor after
    every measurement was started and before its data (a concurrent abort, R-4.4.7.1-01)."""
    started = [start(recorder, f"{a}{code}!") for a in addresses]
    for text in (meddle or {}).values():
        recorder.transact(text)
    link = recorder.link
    ends = [m.reply_end + m.ttt for m in started if m.reply_end is not None and m.ttt]
    link.wait_until(max([link.now(), *ends]) + 0.1)
    for m in started:
        recorder.collect(m, force_break=True)
    return started


def as_heard(bus: SimBus) -> list[Event]:
    """The bus's events as a capture holds them: origin ``bus``, no notes."""
    return [replace(e, origin=BUS) for e in bus.transcript.events if e.kind is not EventKind.NOTE]


def record(
    path: Path,
    addresses: str = ADDRESSES,
    *,
    faults: Mapping[str, Sequence[str]] | None = None,
    code: str = "C",
    meddle: Mapping[str, str] | None = None,
) -> Path:
    """The whole exchange (``aI!`` each, a concurrent round) as ``path``/transcript.jsonl,
    every event of origin ``bus``; returns the file."""
    bus, recorder = bus_of_sensors(addresses, faults)
    for a in addresses:
        recorder.identify(a)
    concurrent_round(recorder, addresses, code=code, meddle=meddle)
    path.mkdir(parents=True, exist_ok=True)
    out = path / "transcript.jsonl"
    write_recording(out, as_heard(bus))
    return out
