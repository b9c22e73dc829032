"""The tool recorder's measurements: service request / ttt waits and D0..Dn / DB0.. collection."""

from __future__ import annotations

from conformance.protocol import commands as cmds
from conformance.protocol.binary import DataType, build_packet, empty_packet
from conformance.protocol.timing import NO_BREAK_WINDOW
from conformance.tool_recorder.policy import Policy
from conformance.tool_recorder.records import Measurement
from tests.support.own_time import own_time
from tests.tool_recorder.test_scripted_sensor import Burst, ScriptedSensor, rig, then_sr, with_crc


def first_d(m: Measurement):
    return m.data[0].attempts[0]


def test_measure_with_service_request_sends_d0_at_once_without_break():
    script = {"0M!": [then_sr("00052\r\n", after=2.0)], "0D0!": ["0+1.5-2.25\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0"))
    assert (m.ttt, m.count) == (5, 2)
    assert m.values == ["+1.5", "-2.25"] and m.complete
    assert "".join(chr(e.char7) for e in m.waited_events) == "0\r\n"
    assert m.service_request_end is not None
    assert m.service_request_end - m.reply_end > 2.0
    d0 = first_d(m)
    assert d0.break_event is None  # R-4.4.5-05, R-7.1-01
    assert d0.command_events[0].start - m.service_request_end < NO_BREAK_WINDOW


def test_measure_without_service_request_breaks_at_ttt():
    script = {"0M!": ["00021\r\n"], "0D0!": ["0+7\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0"))
    assert m.service_request_end is None and m.waited_events == []
    d0 = first_d(m)
    assert d0.break_event is not None
    assert d0.break_event.start >= m.reply_end + 2  # R-4.4.5-04: never before ttt
    assert m.values == ["+7"]


def test_ttt_zero_reads_d0_at_once():
    script = {"0M1!": ["00001\r\n"], "0D0!": ["0-0.5\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0", group=1))
    d0 = first_d(m)
    assert d0.break_event is None
    assert d0.command_events[0].start - m.reply_end < NO_BREAK_WINDOW
    assert m.values == ["-0.5"]


def test_late_service_request_is_recorded_and_answered():
    script = {"0V!": [then_sr("00011\r\n", after=1.3)], "0D0!": ["0+1\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.verify("0"))
    assert m.service_request_end is not None
    assert m.service_request_end - m.reply_end > 1.0  # late: evidence for R-4.4.6-04
    assert first_d(m).break_event is None
    assert m.values == ["+1"]


def test_wait_ttt_ignores_but_records_the_service_request():
    # The SR comes just before ttt: answering it would need no break, waiting out ttt does.
    script = {"0M!": [then_sr("00031\r\n", after=2.95)], "0D0!": ["0+2\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0"), wait="ttt")
    assert m.service_request_end is not None
    d0 = first_d(m)
    assert d0.break_event is not None and d0.break_event.start >= m.reply_end + 3


def test_wait_none_probes_d0_at_once():
    script = {"0M!": ["00101\r\n"], "0D0!": ["0\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0"), wait="none")
    d0 = first_d(m)
    assert d0.break_event is None
    assert d0.command_events[0].start - m.reply_end < NO_BREAK_WINDOW


def test_concurrent_waits_ttt_records_chatter_then_breaks():
    reply = Burst("000302\r\n")
    chatter = Burst("zz", at=reply.end_offset + 1.0)
    script = {"0C!": [[reply, chatter]], "0D0!": ["0+1+2\r\n"]}
    master, _ = rig(ScriptedSensor(script, break_cancels=False))
    m = master.measure(cmds.concurrent("0"))
    assert (m.ttt, m.count) == (3, 2)
    assert "".join(chr(e.char7) for e in m.waited_events) == "zz"
    d0 = first_d(m)
    assert d0.break_event is not None and d0.break_event.start >= m.reply_end + 3  # R-4.4.7-06
    assert m.values == ["+1", "+2"]


def test_99_value_concurrent_collected_through_d9():
    values = [f"+{i}" for i in range(99)]
    script = {"0C!": ["000099\r\n"]}
    for i in range(10):
        script[f"0D{i}!"] = ["0" + "".join(values[10 * i : 10 * i + 10]) + "\r\n"]
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.concurrent("0"))
    assert m.values == values and m.complete
    assert [ex.text for ex in m.data] == [f"0D{i}!" for i in range(10)]


def test_collection_stops_at_d9_for_concurrent():
    script = {"0C!": ["000050\r\n"]}
    for i in range(12):
        script[f"0D{i}!"] = ["0+1\r\n"]
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.concurrent("0"))
    assert len(m.data) == 10 and not m.complete


def test_high_volume_ascii_past_d9_without_leading_zeros_and_crc_stripped():
    script = {"0HA!": ["0000030\r\n"]}
    for i in range(15):
        script[f"0D{i}!"] = [with_crc(f"0+{2 * i}+{2 * i + 1}")]
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.high_volume_ascii("0"))
    assert [ex.text for ex in m.data] == [f"0D{i}!" for i in range(15)]  # R-5.1-04
    assert m.values == [f"+{i}" for i in range(30)]
    assert all(ex.ok and len(ex.attempts) == 1 for ex in m.data)


def test_high_volume_binary_packets_read_8n1():
    p0 = build_packet("0", DataType.INT16, [-1] * 8)
    p1 = build_packet("0", DataType.FLOAT32, [1.5] * 4)
    script = {"0HB!": ["0000012\r\n"], "0DB0!": [p0], "0DB1!": [p1]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.high_volume_binary("0"))
    assert m.packets == [p0, p1]
    assert m.binary_value_count == 12 and m.complete
    assert all(ex.binary and ex.ok for ex in m.data)
    assert m.data[0].reply_bytes == p0 and 0xFF in p0  # 8 data bits, no parity stripping


def test_high_volume_binary_stops_at_empty_packet():
    p0 = build_packet("0", DataType.UINT8, [1, 2, 3])
    script = {"0HB!": ["0000020\r\n"], "0DB0!": [p0], "0DB1!": [empty_packet("0")]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.high_volume_binary("0"))
    assert [ex.text for ex in m.data] == ["0DB0!", "0DB1!"]
    assert m.binary_value_count == 3 and not m.complete  # R-5.2-08


def test_binary_packet_with_bad_crc_is_retried():
    good = build_packet("0", DataType.UINT8, [7])
    bad = good[:-1] + bytes([good[-1] ^ 1])
    script = {"0HB!": ["0000001\r\n"], "0DB0!": [bad, good]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.high_volume_binary("0"))
    assert [a.reason for a in m.data[0].attempts] == ["invalid: binary CRC mismatch", "ok"]
    assert m.complete


def test_empty_d_reply_stops_collection():
    script = {"0M!": ["00003\r\n"], "0D0!": ["0\r\n"]}
    master, _ = rig(ScriptedSensor(script), policy=Policy.golden())
    m = master.measure(cmds.measure("0"))
    assert len(m.data) == 1 and m.data[0].ok and m.values == [] and not m.complete


def test_observer_looks_one_index_past_an_empty_reply():
    script = {"0M!": ["00003\r\n"], "0D0!": ["0\r\n"], "0D1!": ["0+1+2+3\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    m = master.measure(cmds.measure("0"))
    assert [ex.text for ex in m.data] == ["0D0!", "0D1!"] and m.values == ["+1", "+2", "+3"]


def test_invalid_start_reply_gives_no_collection():
    master, _ = rig(ScriptedSensor({"0M!": ["0001\r\n"]}))
    m = master.measure(cmds.measure("0"))
    assert m.ttt is None and m.data == [] and not m.start.ok
    assert m.start.last.reason.startswith("invalid: not 4 digits")


def test_ttt_999_completes_fast_on_the_sim_bus():
    script = {"0M!": ["09991\r\n"], "0D0!": ["0+9\r\n"]}
    master, _ = rig(ScriptedSensor(script))
    with own_time() as took:  # less any wait for a CPU: a busy machine does not stretch it
        m = master.measure(cmds.measure("0"))
    assert took.seconds < 1.0, took
    assert first_d(m).break_event.start >= m.reply_end + 999
    assert m.values == ["+9"]


def test_abort_by_break_then_collect_records_empty_reply():
    sensor = ScriptedSensor({"0M!": [then_sr("00101\r\n", after=5)], "0D0!": ["0\r\n"]})
    master, bus = rig(sensor)
    m = master.measure(cmds.measure("0"), collect=False, wait="none")
    master.abort(m)
    master.collect(m, force_break=False)
    assert m.aborted_by == "break" and m.values == [] and m.data[0].ok
    assert first_d(m).break_event is None
    assert len(sensor.breaks) == 2  # the M's own break, then the abort
