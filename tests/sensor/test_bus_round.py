"""The bus cases' stimulus on a simulated bus of three: every measurement runs at once and
every sensor's data come back whole, the DUT's last, with the others' talk in its wait."""

from __future__ import annotations

from conformance.judges.bus import sensor_lines
from conformance.ports import open_sim, parse_sim
from conformance.sensor.bus_round import concurrent_round
from conformance.tool_recorder import ToolRecorder
from conformance.transcript import TOOL, decode_7e1


def test_every_measurement_runs_at_once_and_comes_back_whole():
    link = open_sim(parse_sim("sim://?sensors=0,1,3")).link
    made = concurrent_round(ToolRecorder(link), "1", ["0", "3"])
    assert made.control.reply_text == "1\r\n"
    for m in (made.dut, *made.others.values()):
        assert m.count == 20 and m.value_count == 20  # no command to itself aborted it
    assert [ex.reply_text for ex in made.acks.values()] == ["0\r\n", "3\r\n"]
    # the DUT's data were asked for last, after the others' whole collection
    assert made.dut.data[0].start > max(m.data[-1].start for m in made.others.values())
    # the others' replies are all inside its wait; and all of them came while it ran
    assert len(made.other_replies()) == 2 + 2 + 4  # a!, aC!, D0 and D1 of each
    assert len(made.other_replies(running=True)) == 4  # a! and aC! of each, before its ttt
    heard = decode_7e1([e for e in made.window if e.origin != TOOL])
    assert heard.startswith("0\r\n")  # sensor 0's a! reply first, the DUT itself silent
    assert {chr(line[0].char7) for line in sensor_lines(made.window)} == {"0", "3"}
