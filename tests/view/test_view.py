"""The role-neutral view: one segmentation for both roles, the reasons it gives for the splits
the wire leaves open, and direction inferred from the protocol when a recording has none."""

from __future__ import annotations

import dataclasses

import pytest

from conformance import emulator
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.recorder.played import SensorSpec, Spoil
from conformance.sim.bus import SimBus, SimLink
from conformance.sim.line_monitor import LineMonitor
from conformance.tool_recorder import Policy, ToolRecorder
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view.direction import infer_directions
from conformance.view.segments import read_view
from conformance.view.sides import BUS, RECORDER, SENSOR


class Wire:
    def __init__(self) -> None:
        self.events: list[Event] = []
        self.t = 0.0

    def brk(self) -> Wire:
        self.events.append(Event(EventKind.BREAK, TOOL, self.t, self.t + 0.013))
        self.t += 0.022
        return self

    def chars(self, text: str, origin: str, delay_ms: float = 0.0, gap_ms: float = 0.0) -> Wire:
        self.t += delay_ms / 1e3
        for c in text:
            self.events.append(
                Event(EventKind.CHAR, origin, self.t, self.t + CHAR_TIME, to_wire_7e1(ord(c)))
            )
            self.t += CHAR_TIME + gap_ms / 1e3
        return self


def test_one_transmission_per_command_with_its_reply_and_service_request():
    w = Wire().brk().chars("0M!", TOOL).chars("00013\r\n", DUT, 9.0).chars("0\r\n", DUT, 500)
    w.chars("0D0!", TOOL, 20).chars("0+1+2+3\r\n", DUT, 9.0)
    view = read_view(w.events)
    first, second = view.transmissions
    assert (first.text, first.break_event is not None) == ("0M!", True)
    assert len(first.reply) == 7 and len(first.after) == 3
    assert [sr.address for sr in view.service_requests()] == ["0"]
    assert second.break_event is None and len(second.reply) == 9
    assert view.ambiguities() == []


@pytest.mark.parametrize(
    ("build", "reason"),
    [
        (lambda w: w.brk().chars("0!", TOOL).chars("0\r\n", DUT, 9.0, gap_ms=5.0), "a gap of"),
        (lambda w: w.brk().chars("1!", TOOL).chars("0\r\n", DUT, 9.0), "address mismatch"),
        (lambda w: w.brk().chars("0\r\n", DUT, 9.0).chars("0!", TOOL), "no command to answer"),
        (lambda w: w.brk().chars("0I", TOOL).chars("0\r\n", DUT, 9.0), "has no '!'"),
        (lambda w: w.brk().chars("0!", TOOL).chars("0\r\nxx", DUT, 9.0), "no service request"),
    ],
)
def test_every_ambiguous_split_says_why(build, reason):
    ambiguities = read_view(build(Wire()).events).ambiguities()
    assert any(reason in a.reason for a in ambiguities), [str(a) for a in ambiguities]


def test_two_talkers_are_flagged():
    w = Wire().brk().chars("0M!", TOOL)
    w.events.append(Event(EventKind.CHAR, DUT, w.t - 2 * CHAR_TIME, w.t - CHAR_TIME, 0x30))
    assert any("two talkers" in a.reason for a in read_view(w.events).ambiguities())


def _sensor_role(faults: tuple[str, ...]) -> list[Event]:
    _, link, _ = emulator.sim_sensor(faults=faults)
    master = ToolRecorder(link)
    master.acknowledge(), master.identify()
    for text in ("0M!", "0MC!", "0C!", "0V!", "0HB!"):
        master.measure(cmds.parse_command(text))
    master.transact("0XSN!"), master.transact("1I!")
    return link.transcript.events


def _recorder_role(spec: SensorSpec) -> list[Event]:
    link = SimLink(SimBus([LineMonitor(), spec.build()]))
    master = ToolRecorder(link, Policy.golden())
    master.transact("0!"), master.measure(cmds.measure("0", crc=True))
    master.measure(cmds.concurrent("0"))
    return link.transcript.events


RUNS = {
    "sensor clean": lambda: _sensor_role(()),
    "sensor wrong-crc": lambda: _sensor_role(("wrong-crc",)),
    "sensor response-too-late": lambda: _sensor_role(("response-too-late",)),
    "sensor inter-char-gap": lambda: _sensor_role(("inter-char-gap",)),
    "sensor missing-crlf": lambda: _sensor_role(("missing-crlf",)),
    "recorder clean": lambda: _recorder_role(SensorSpec()),
    "recorder unheard": lambda: _recorder_role(SensorSpec(unheard=2)),
    "recorder crc spoilt": lambda: _recorder_role(
        SensorSpec(spoil=Spoil("crc"), spoil_command="0D0!")
    ),
}


@pytest.mark.parametrize("name", RUNS)
def test_inferred_direction_agrees_with_the_true_origins(name):
    events = [e for e in RUNS[name]() if e.kind is not EventKind.NOTE]
    stripped = [dataclasses.replace(e, origin=BUS) for e in events]
    inferred = infer_directions(stripped)
    assert len(inferred) == len(events)
    truth = [RECORDER if e.origin == TOOL else SENSOR for e in events]
    sure_wrong = [
        (e.start, d.how)
        for (e, d), t in zip(inferred, truth, strict=True)
        if d.sure and d.side != t
    ]
    agree = sum(d.side == t for (_, d), t in zip(inferred, truth, strict=True))
    assert not sure_wrong
    assert agree / len(events) > 0.99, f"{agree} of {len(events)}"
    assert all(d.how for _, d in inferred)  # every direction says how it was found


def test_a_capture_without_origins_reads_into_the_same_view():
    events = _sensor_role(())
    stripped = [dataclasses.replace(e, origin=BUS) for e in events]
    known, inferred = read_view(events), read_view(stripped)
    assert [(t.text, len(t.reply)) for t in inferred.transmissions] == [
        (t.text, len(t.reply)) for t in known.transmissions
    ]
    assert inferred.undirected == []
