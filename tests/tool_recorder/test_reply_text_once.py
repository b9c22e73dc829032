"""Issue 22, matrix18: a reply's text decoded once and carried with it. The engine decodes
each 7E1 reply it judges once, checks it from that text (``validity.check_ascii(text=...)``)
and leaves the text on the attempt (``Attempt.reply_text``), which every later reader asks
(the buffer watch, ``Exchange.reply_text`` and the judges through it). The text carried is
``decode_7e1`` of the reply's events at every moment, also after the list grew in place
or was replaced."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.protocol import commands as cmds
from conformance.tool_recorder import ToolRecorder, validity
from conformance.tool_recorder.records import Attempt, Exchange
from conformance.transcript import DUT, TOOL, Event, EventKind, decode_7e1
from tests.support.hand_events import chars

CHAR = 8.333e-3


def test_check_ascii_given_the_text_answers_as_without():
    command = cmds.parse_command("0D0!")
    for text in ("0+1\r\n", "0+1", "1+1\r\n", "0+1.2.3\r\n"):
        events = chars(DUT, text, 0.02)
        args = dict(address="0", command_end=0.01, gap_limit=0.0104, crc_expected=False)
        without = validity._ascii_problem(command, events, "0", 0.01, 0.0104, False, False)
        given_text = validity._ascii_problem(
            command, events, "0", 0.01, 0.0104, False, False, decode_7e1(events)
        )
        assert given_text == without
        assert validity.check_ascii(command, events, **args, text=text) == without


def _attempt(events: list[Event]) -> Attempt:
    sent = chars(TOOL, "0D0!", 0.0)
    return Attempt(None, sent, events, "ok", 1.0)


def test_attempt_reply_text_follows_its_events():
    events = chars(DUT, "0+1", 0.02)
    attempt = _attempt(events)
    assert attempt.reply_text == "0+1"
    attempt.reply_events += chars(DUT, "\r\n", 0.05)  # grown in place (a golden recorder)
    assert attempt.reply_text == "0+1\r\n"
    attempt.reply_events = chars(DUT, "0+22\r\n", 0.02)  # replaced whole
    assert attempt.reply_text == "0+22\r\n"
    attempt.knows_reply_text("0+22\r\n")
    attempt.reply_events.append(Event(EventKind.BREAK, DUT, 0.1, 0.2))  # no character
    assert attempt.reply_text == decode_7e1(attempt.reply_events) == "0+22\r\n"
    attempt.reply_events.append(chars(DUT, "x", 0.3)[0])
    assert attempt.reply_text == "0+22\r\nx"
    empty = _attempt([])
    assert empty.reply_text == ""
    exchange = Exchange(cmds.parse_command("0D0!"), "0D0!", [empty, attempt])
    assert exchange.reply_text == decode_7e1(exchange.reply_events)


def test_the_engine_carries_each_reply_as_decoded():
    """Every attempt of a run of commands against the emulator, clean and with faults that
    spoil replies (parity, CRC, marking), carries its events' decode_7e1."""
    from conformance.emulator import sim_sensor

    for faults in ((), ("parity-error",), ("wrong-crc",), ("inter-char-gap",)):
        _, link, _ = sim_sensor(faults=faults)
        master = ToolRecorder(link)
        exchanges = [master.acknowledge(), master.identify()]
        m = master.measure(cmds.measure("0", crc=True))
        exchanges += [m.start, *m.data]
        exchanges.append(master.transact("0XHELP!"))
        attempts = [a for ex in exchanges for a in ex.attempts]
        assert any(a.reply_events for a in attempts)
        for attempt in attempts:
            assert "_text" in attempt.__dict__ or not attempt.reply_events or not attempt.ok
            assert attempt.reply_text == decode_7e1(attempt.reply_events)


@settings(max_examples=600, deadline=None)
@given(st.text(alphabet=st.characters(max_codepoint=0x200), max_size=12))
def test_crc_characters_searched_as_asked_one_by_one(body):
    """``_crc_problem`` finds a CRC character in a reply that should have none by a search
    in C (matrix18); it finds one exactly when ``is_crc_char`` says so of a character after
    the address, in any text (past 7 bits too)."""
    from conformance.protocol.crc import CRC_CHAR, is_crc_char

    found = CRC_CHAR.search(body, 1) is not None
    assert found == any(is_crc_char(c) for c in body[1:])
    problem = validity._crc_problem(body, False)
    assert (problem == "unexpected CRC characters") == found
