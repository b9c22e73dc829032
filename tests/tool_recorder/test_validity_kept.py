"""``validity.check_ascii`` keeps its last answers: the tool recorder and the view's records
of the stimulus ask it about the same reply, so the second asks nothing new; an answer is
given again only for the same question about the same characters (compared, not counted)."""

from __future__ import annotations

import dataclasses

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.ports import open_sim, parse_sim
from conformance.protocol.commands import parse_command
from conformance.sensor.session import SensorSession
from conformance.tool_recorder import validity
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1

COMMANDS = [None, parse_command("0D0!"), parse_command("0M!"), parse_command("1D0!")]
TEXTS = ["0+1\r\n", "0+2\r\n", "00011\r\n", "1+1\r\n", "0+1\n\r", "0\r\n"]


def _reply(text: str, start: float, gap: float, flip: int | None) -> list[Event]:
    out = []
    t = start
    for i, c in enumerate(text):
        wire = to_wire_7e1(ord(c)) ^ (0x80 if i == flip else 0)
        out.append(Event(EventKind.CHAR, DUT, t, t + 0.008333, wire))
        t += 0.008333 + gap
    return out


questions = st.tuples(
    st.sampled_from(COMMANDS),
    st.sampled_from(TEXTS),
    st.sampled_from([0.01, 0.02]),  # the reply's start
    st.sampled_from([0.0, 0.003]),  # gap between its characters
    st.sampled_from([None, 1]),  # a parity error
    st.sampled_from([0.009, 0.011]),  # command end
    st.sampled_from([None, True, False]),  # crc expected
    st.booleans(),  # the same list asked again, or a copy
    st.booleans(),  # the command object parse_command keeps, or an equal one made apart
)


@settings(max_examples=200, deadline=None)
@given(st.lists(questions, min_size=1, max_size=40))
def test_kept_answers_are_the_answers(asked):
    validity._JUDGED.clear()
    for command, text, start, gap, flip, end, crc, copy, apart in asked:
        if apart and command is not None:
            command = dataclasses.replace(command)  # equal, not the same object
        events = _reply(text, start, gap, flip)
        if copy:
            events = list(events)
        kw = dict(address="0", command_end=end, gap_limit=0.00873, crc_expected=crc)
        assert validity.check_ascii(command, events, **kw) == validity._ascii_problem(
            command, events, "0", end, 0.00873, crc, False
        )


def test_same_count_other_characters_not_taken_for_kept():
    validity._JUDGED.clear()
    kw = dict(address="0", command_end=0.009, gap_limit=0.00873)
    good = _reply("0+1\r\n", 0.02, 0.0, None)
    bad = _reply("0+1\r\n", 0.02, 0.0, 2)  # same count, same first start: parity error
    assert validity.check_ascii(parse_command("0D0!"), good, **kw) is None
    assert validity.check_ascii(parse_command("0D0!"), bad, **kw) == "parity error in character 3"


def test_the_views_records_ask_nothing_new(monkeypatch):
    """A stimulus's reply is worked out once: by the tool recorder; the view's record of it
    (``SensorSession._rebuilt``) is given the kept answer."""
    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    worked = []
    original = validity._ascii_problem

    def counted(*args):
        worked.append(args[1])
        return original(*args)

    monkeypatch.setattr(validity, "_ascii_problem", counted)
    ex = session.exchange("I")
    assert ex.ok and ex.reply_text.startswith("0")
    assert len(worked) == 1


def test_an_answer_kept_for_a_command_gone_is_not_given_to_another():
    """The kept answers know a command by its ``id``: one made after the first is gone may
    get its ``id``, and must not get its answer (the command kept beside it is compared)."""
    validity._JUDGED.clear()
    kw = dict(address="0", command_end=0.009, gap_limit=0.00873)
    reply = _reply("0+1\r\n", 0.02, 0.0, None)
    first = dataclasses.replace(parse_command("0M!"))  # answered atttn: '0+1' is no such reply
    assert validity.check_ascii(first, reply, **kw) is not None
    (key,) = validity._JUDGED
    # a D command under the first one's id, as a new object at its address would be
    other = parse_command("0D0!")
    validity._JUDGED[(id(other), *key[1:])] = validity._JUDGED.pop(key)
    assert validity.check_ascii(other, reply, **kw) is None  # worked out: a D reply is fine
