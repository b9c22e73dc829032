"""A sensor's own break (the emulator's ``break-before-reply``: 12.1 ms of spacing from the
command's end, its reply 20.5 ms after it) through a logic-analyzer capture of the run, as
the fault matrix's ``--through-capture`` judges it: the export puts it on the bus channel
alone (not the recorder's TX), the decoder gives it the sensor's origin, and the replay of
the decoded capture plays it where it was. Before, the replay played only the sensor's
characters of a capture (its breaks carry no :data:`SENSOR_BREAK` text there), the break was
gone from the replayed line and R-7.0-09 PASSed through the capture on the reply at 20.5 ms
where the live run FAILed it at 0.00 ms."""

from __future__ import annotations

import pytest

from conformance.capture.decode import decode_capture
from conformance.capture.export import TOOL_CHANNEL, export_events
from conformance.emulator.sim import sim_sensor
from conformance.replay.sensor import RecordedSensor
from conformance.sim.bus import SENSOR_BREAK, SimBus, SimLink
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1

SAMPLE = 1 / 100_000  # the export's default sample rate


def _exchange(link: SimLink) -> float:
    """The tool's break, 9 ms of marking, ``0!`` and 0.1 s of listening; the command's end."""
    link.send_break(0.0125)
    link.wait_until(link.now() + 0.009)
    end = link.write(bytes(to_wire_7e1(ord(c)) for c in "0!"))[-1].end
    link.receive(link.now() + 0.1)
    return end


def _wire(events: list[Event]) -> list[Event]:
    return [e for e in events if e.kind in (EventKind.CHAR, EventKind.BREAK)]


@pytest.fixture
def decoded(tmp_path) -> list[Event]:
    _, link, _ = sim_sensor(faults=("break-before-reply",))
    _exchange(link)
    path = str(tmp_path / "run.sr")
    export_events(link.transcript.events, path, "sr", tool_channel=True)
    return decode_capture(path, tx_channel=TOOL_CHANNEL).events


def test_the_capture_keeps_the_sensors_break_as_the_sensors(decoded):
    wire = _wire(decoded)
    assert [(e.kind, e.origin) for e in wire] == [
        (EventKind.BREAK, TOOL),
        (EventKind.CHAR, TOOL),
        (EventKind.CHAR, TOOL),
        (EventKind.BREAK, DUT),
        (EventKind.CHAR, DUT),
        (EventKind.CHAR, DUT),
        (EventKind.CHAR, DUT),
    ]
    command_end, own, reply = wire[2].end, wire[3], wire[4]
    assert own.start - command_end == pytest.approx(0.0, abs=2 * SAMPLE)
    assert own.duration == pytest.approx(12.1e-3, abs=2 * SAMPLE)
    assert reply.start - command_end == pytest.approx(20.5e-3, abs=2 * SAMPLE)


def test_the_decoded_capture_replays_the_sensors_break_where_it_was(decoded):
    replay = SimLink(SimBus([RecordedSensor(decoded)]))
    command_end = _exchange(replay)
    again = _wire(replay.transcript.events)
    breaks = [e for e in again if e.kind is EventKind.BREAK and e.origin != TOOL]
    assert [(b.origin, b.text) for b in breaks] == [(DUT, SENSOR_BREAK)]
    assert breaks[0].start - command_end == pytest.approx(0.0, abs=2 * SAMPLE)
    assert breaks[0].duration == pytest.approx(12.1e-3, abs=2 * SAMPLE)
    reply = [e for e in again if e.kind is EventKind.CHAR and e.origin != TOOL]
    assert len(reply) == 3 and reply[0].start - command_end == pytest.approx(
        20.5e-3, abs=3 * SAMPLE
    )
