"""A D command whose replies were all refused is read for its values from the reply before a
break when the retries after it gave fewer (fault combinations of 2026-12-05): a sensor that
empties its buffer at a break (buffer-cleared-by-break) and puts a CRC where none belongs, or
none where one does, delivered the values to the first try, but the tool read the empty
reply to the retry after the break, so R-4.4.5-03, R-4.4.5.1-03, R-4.4.7-05, R-4.4.8-03 and
R-4.4.8-04 FAILed for data R-4.4.5-10 alone had lost. The empty replies stay in the
attempts; a reply that was accepted, and retries with no break between, are read as before,
unless the accepted reply is empty after a try that held values (buffer-cleared-after-read
+ value-missing-sign, seed 4061: :func:`~conformance.tool_recorder.records.emptied`).
The view's rebuilt records read the same (:mod:`conformance.view.rebuilt_records`)."""

from __future__ import annotations

from conformance import emulator
from conformance.protocol import commands as cmds
from conformance.protocol.crc import ascii_crc
from conformance.tool_recorder import ToolRecorder
from conformance.tool_recorder.policy import Policy
from conformance.transcript import decode_7e1, decode_8n1
from conformance.view.rebuilt_records import rebuild_records
from conformance.view.segments import read_view
from tests.tool_recorder.test_scripted_sensor import ScriptedSensor, rig, with_crc

M = cmds.parse_command("0M!")
STRAY_CRC = with_crc("0+1+2+3")  # plain M: a CRC where none belongs, so never accepted
EMPTIED = with_crc("0")  # the same sensor after the break emptied its buffer


def _measured(script: dict, policy: Policy | None = None):
    master, _ = rig(ScriptedSensor({"0M!": ["00003\r\n"], **script}), policy=policy)
    m = master.measure(M)
    rebuilt = rebuild_records(read_view(master.link.transcript.events), master.policy)
    return m, rebuilt.measurements[0]


def test_values_delivered_before_the_break_are_read_not_the_emptied_retry():
    m, rebuilt = _measured({"0D0!": [STRAY_CRC] * 3 + [EMPTIED]})
    d0 = m.data[0]
    assert not d0.ok and len(d0.attempts) == 9  # three sequences, none accepted
    assert m.values == ["+1", "+2", "+3"] and d0.reply_text == STRAY_CRC
    assert len(m.data) == 1  # all announced values in: no D1 probed past an "empty" D0
    # the retries after the break and what they got stay in the records, as evidence
    assert [a.break_event is not None for a in d0.attempts[3::3]] == [True, True]
    assert all(a.reply_events and a.reply_events != d0.judged.reply_events for a in d0.attempts[3:])
    assert (rebuilt.values, rebuilt.data[0].reply_text) == (m.values, d0.reply_text)


def test_an_accepted_empty_retry_after_a_try_that_held_values_is_not_the_one_read():
    """buffer-cleared-after-read + value-missing-sign (seed 4061): the retry an invalid
    reply drew found the buffer emptied and its empty reply was accepted; the values are
    the first try's (R-4.4.8-02 judges them), the empty reply stays in the attempts."""
    m, rebuilt = _measured({"0D0!": [STRAY_CRC] * 3 + ["0\r\n"]})
    d0 = m.data[0]
    assert d0.ok and d0.last.reply_events and decode_7e1(d0.last.reply_events) == "0\r\n"
    assert d0.reply_text == STRAY_CRC and m.values == ["+1", "+2", "+3"] == rebuilt.values


def test_an_accepted_retry_with_fewer_values_is_read_as_before():
    """Noise can make a garbled reply look like more values than the valid retry holds: an
    accepted retry that holds values is the one read."""
    m, rebuilt = _measured({"0D0!": ["0+1+2+3+4\r\n".replace("3+4", "3+4x"), "0+1+2+3\r\n"]})
    assert m.data[0].ok and m.data[0].reply_text == "0+1+2+3\r\n"
    assert m.values == ["+1", "+2", "+3"] == rebuilt.values


def test_an_accepted_empty_first_reply_is_read_as_it_came():
    m, rebuilt = _measured({"0D0!": ["0\r\n"]})
    assert m.data[0].ok and m.data[0].reply_text == "0\r\n" and m.values == [] == rebuilt.values


def test_fewer_values_to_retries_without_a_break_between_are_read_as_before():
    one_value = with_crc("0+1")
    m, rebuilt = _measured({"0D0!": [STRAY_CRC, one_value]}, Policy().but(sequences=1))
    assert len(m.data[0].attempts) == 3 and not m.data[0].ok
    assert m.data[0].reply_text == one_value
    assert m.values[:1] == ["+1"] and rebuilt.values == m.values


def test_a_later_reply_with_as_many_values_is_the_one_read():
    other = "0+1+2+4" + ascii_crc("0+1+2+4") + "\r\n"
    m, _ = _measured({"0D0!": [STRAY_CRC] * 3 + [other]})
    assert m.data[0].reply_text == other and m.values == ["+1", "+2", "+4"]


def test_the_emulated_combination_delivers_its_values_on_the_sim_bus():
    """buffer-cleared-by-break + crc-missing: aMC!'s aD0! lacks its CRC, so it is retried
    after a break, which empties the buffer; the three values came with the first try."""
    _, link, _ = emulator.sim_sensor(faults=("buffer-cleared-by-break", "crc-missing"))
    m = ToolRecorder(link).measure(cmds.parse_command("0MC!"))
    d0 = m.data[0]
    assert m.count == 3 and len(m.values) == 3 and d0.reply_text.startswith("0+22.15")
    assert {decode_7e1(a.reply_events) for a in d0.attempts[3:]} == {"0\r\n"}  # emptied


def test_values_lost_to_plain_retries_before_the_break_are_read_from_the_first_try():
    """buffer-cleared-after-read: the plain retries already found the buffer empty; the
    break that starts the next sequence came after the try that delivered the values."""
    m, rebuilt = _measured({"0D0!": [STRAY_CRC, EMPTIED]})
    assert m.values == ["+1", "+2", "+3"] == rebuilt.values
    assert m.data[0].judged is m.data[0].attempts[0]


def test_only_d_commands_are_read_from_before_a_break():
    master, _ = rig(ScriptedSensor({"0R0!": [STRAY_CRC] * 3 + [EMPTIED]}))
    ex = master.transact("0R0!")
    assert not ex.ok and ex.reply_text == EMPTIED  # the last answered, as before


def test_a_db_packet_delivered_before_the_break_is_read_not_the_emptied_retry():
    """binary-crc-wrong + buffer-cleared-by-break: every packet's CRC is wrong, so each DBn
    is retried after breaks; the break after the last page emptied the buffer, and the
    empty packets to its retries had cost the last page's values (R-5.2-07 FAILed)."""
    _, link, _ = emulator.sim_sensor(faults=("binary-crc-wrong", "buffer-cleared-by-break"))
    m = ToolRecorder(link).measure(cmds.parse_command("0HB!"))
    rebuilt = rebuild_records(read_view(link.transcript.events)).measurements[0]
    assert m.binary_value_count == m.count == rebuilt.binary_value_count
    last = m.data[-1]
    assert not last.ok and last.judged is not last.attempts[-1]
    assert len(decode_8n1(last.attempts[-1].reply_events)) < len(last.reply_bytes)  # emptied
