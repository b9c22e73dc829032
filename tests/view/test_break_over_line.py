"""A recorder's break over a sensor's line still coming, read from a capture that does not
say who sent what (passive judging of the bus alone). The sensor cannot hear a break while
it sends: the rest of its character under the break ends after it, and a UART reads that
tail as a character ('~' 1.1 ms after the break) before the recorder's own command 20 ms
later. Read as the recorder's, it made '~0D0!' its command: R-7.0-06 'marking after the
break: 0.50 ms', R-7.0-13 (14.17 ms inside the command) and R-4.3-01 ('~' not an address)
FAILed on the sensor's characters (breaks-over-long-reply, whose live run and capture with
the recorder's TX channel PASS all three)."""

from __future__ import annotations

import json
from pathlib import Path

from conformance.capture.export import export_events
from conformance.cli import main
from conformance.matrices.roundtrip import live_run
from conformance.transcript import EventKind
from conformance.view.direction import infer_directions
from conformance.view.sides import BUS, RECORDER, SENSOR
from tests.view.test_view import Wire


def test_r_7_0_06_a_tail_after_a_break_over_a_line_is_not_the_recorders_command():
    wire = Wire().brk().chars("0D0!", BUS).chars("0+10.0", BUS, delay_ms=9.0)
    wire.t -= 0.0004  # the break begins over the line's next character
    wire.brk()
    wire.t = wire.events[-1].end + 1.1e-3
    wire.chars("~", BUS).chars("0D0!", BUS, delay_ms=14.0)
    found = [(e, d) for e, d in infer_directions(wire.events) if e.kind is EventKind.CHAR]
    tail, command = found[-5], found[-4:]
    assert tail[1].side == SENSOR and not tail[1].sure, tail[1].how
    assert all(d.side == RECORDER for _, d in command)


def test_a_fragment_after_a_break_over_a_quiet_line_is_still_the_recorders():
    """No line coming when the break began: a first run without '!' stays the recorder's."""
    wire = Wire().brk().chars("0D0!", BUS).chars("0+10.0\r\n", BUS, delay_ms=9.0)
    wire.t += 0.050
    wire.brk()
    wire.t = wire.events[-1].end + 1.1e-3
    wire.chars("0D", BUS)
    found = [(e, d) for e, d in infer_directions(wire.events) if e.kind is EventKind.CHAR]
    assert all(d.side == RECORDER and d.sure for _, d in found[-2:])


def test_r_7_0_06_judged_passively_on_the_bus_alone_is_the_live_runs_pass(tmp_path: Path):
    _, events = live_run(
        tmp_path / "live", "sim://?recorder-faults=breaks-over-long-reply", role="recorder"
    )
    capture = tmp_path / "bus.sr"
    export_events(events, str(capture), "sr")  # no TX channel: directions inferred
    out = tmp_path / "judged"
    main(["judge", str(capture), "--passive", "--role", "recorder", "--report-dir", str(out)])
    data = json.loads((out / "verdicts.json").read_text())
    verdicts = {r["id"]: r["verdict"] for r in data["requirements"]}
    assert verdicts["R-7.0-06"] == "PASS", verdicts
    assert verdicts["R-7.0-13"] == verdicts["R-4.3-01"] == "PASS", verdicts
    assert verdicts["R-7.2-06"] == "FAIL"
