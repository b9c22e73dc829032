"""Issue 22, matrix16: ``unbroken_acknowledge_answered`` (the control behind R-7.0-03/-04's
unbroken foreign command) looks only where the run's seven-bit characters, in time order,
spell ``a!a<CR><LF>``, and checks each such place whole. Its first look reads the whole run
so far (10^4..10^5 events a fault-matrix row), which sorting a copy and decoding every pair
of the tool's characters made 4..28 ms a run. The answer must be the one the scan of every
place gave (kept here as the reference): on transcripts made up around every condition
(notes, breaks, stamps out of order, bad parity, gaps at the 87 ms and first-character
limits, other addresses, wires that are no byte) and on runs of the sim."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.protocol.timing import CHAR_TIME, NO_BREAK_WINDOW
from conformance.transcript import DUT, TOOL, Event, EventKind, decode_7e1, to_wire_7e1
from testcases.sensor.test_7_timing import unbroken_acknowledge_answered
from tests.support.case_verdicts import sim_session

FIRST_CHAR = 30e-3


def _reference(events, address: str, first_char: float) -> bool:
    """The scan of every place, as it was before matrix16."""
    wire = sorted((e for e in events if e.kind is not EventKind.NOTE), key=lambda e: e.start)
    want = f"{address}\r\n"
    for i in range(1, len(wire) - 4):
        a, bang, before = wire[i], wire[i + 1], wire[i - 1]
        if not (
            a.origin == TOOL
            and bang.origin == TOOL
            and a.kind is EventKind.CHAR
            and bang.kind is EventKind.CHAR
            and decode_7e1((a, bang)) == f"{address}!"
            and before.kind is EventKind.CHAR
            and before.origin != TOOL
            and a.start - before.end <= NO_BREAK_WINDOW
        ):
            continue
        reply = wire[i + 2 : i + 5]
        if (
            all(e.kind is EventKind.CHAR and e.origin != TOOL and e.parity_ok for e in reply)
            and decode_7e1(reply) == want
            and reply[0].start - bang.end <= first_char
        ):
            return True
    return False


CHARS = "0!\r\n1x"
GAPS = [0.0, 1e-3, FIRST_CHAR, FIRST_CHAR + 1e-6, NO_BREAK_WINDOW, NO_BREAK_WINDOW + 1e-6, -5e-3]


@st.composite
def transcripts(draw) -> list[Event]:
    """Events mostly spelling the control and near misses of it."""
    events: list[Event] = []
    t = 0.0
    for _ in range(draw(st.integers(0, 24))):
        kind = draw(st.sampled_from([EventKind.CHAR] * 6 + [EventKind.BREAK, EventKind.NOTE]))
        origin = draw(st.sampled_from([TOOL, DUT]))
        t += draw(st.sampled_from(GAPS))
        if kind is EventKind.CHAR:
            wire = to_wire_7e1(ord(draw(st.sampled_from(CHARS))))
            if draw(st.integers(0, 9)) == 0:
                wire ^= 0x80  # a parity error
            if draw(st.integers(0, 60)) == 0:
                wire = 0x1FF  # a made-up event: no byte
            events.append(Event(kind, origin, t, t + CHAR_TIME, wire))
            t += CHAR_TIME
        elif kind is EventKind.BREAK:
            events.append(Event(kind, TOOL, t, t + 12e-3))
            t += 12e-3
        else:
            events.append(Event(kind, TOOL, t - 0.02, t - 0.02, text="a note"))
    return events


def _control(t: float, gap: float, start: float, address: str = "0") -> list[Event]:
    """The DUT's last character, then ``a!`` ``gap`` after it, then ``a<CR><LF>``."""
    out = [Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, to_wire_7e1(ord("\n")))]
    t += CHAR_TIME + gap
    for c in f"{address}!":
        out.append(Event(EventKind.CHAR, TOOL, t, t + CHAR_TIME, to_wire_7e1(ord(c))))
        t += CHAR_TIME
    t += start - CHAR_TIME
    for c in f"{address}\r\n":
        out.append(Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, to_wire_7e1(ord(c))))
        t += CHAR_TIME
    return out


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    transcripts(),
    st.lists(
        st.tuples(st.sampled_from(GAPS), st.sampled_from(GAPS[:4]), st.integers(0, 40)),
        max_size=3,
    ),
    st.sampled_from(["0", "1", "", "01"]),
    st.tuples(st.integers(0, 40), st.integers(0, 40)),
)
def test_the_places_looked_at_give_the_answer_of_every_place(made, controls, address, swap):
    events = list(made)
    t = events[-1].end if events else 0.0
    for gap, start, at in controls:
        control = _control(t + 0.01, gap, start + CHAR_TIME)
        events[at:at] = control
        t = control[-1].end
    i, j = swap
    if i < len(events) and j < len(events):
        events[i], events[j] = events[j], events[i]  # out of time order: sorted first
    assert unbroken_acknowledge_answered(events, address, FIRST_CHAR) == _reference(
        events, address, FIRST_CHAR
    )


def test_a_control_at_the_limits_is_found_as_before() -> None:
    for gap in (NO_BREAK_WINDOW, NO_BREAK_WINDOW + 1e-9):
        for start in (FIRST_CHAR + CHAR_TIME, FIRST_CHAR + CHAR_TIME + 1e-9):
            events = _control(0.0, gap, start)
            expected = gap <= NO_BREAK_WINDOW and start - CHAR_TIME <= FIRST_CHAR
            assert unbroken_acknowledge_answered(events, "0", FIRST_CHAR) is expected
            assert _reference(events, "0", FIRST_CHAR) is expected


def test_runs_of_the_sim_are_answered_as_before() -> None:
    for faults in ("", "no-follow-up-without-break", "wrong-crc"):
        session = sim_session(faults)
        session.master.transact(f"{session.address}!", force_break=True)
        session.master.raw(f"{session.address}!", break_first=False)
        events = session.link.transcript.events
        for address in ("0", "1"):
            got = unbroken_acknowledge_answered(events, address, FIRST_CHAR)
            assert got == _reference(events, address, FIRST_CHAR)
        shown = faults != "no-follow-up-without-break"  # deaf to a! without a break
        assert unbroken_acknowledge_answered(events, "0", FIRST_CHAR) is shown


def test_a_control_recorded_out_of_order_is_found_in_time_order() -> None:
    """The transcript's order is not the wire's (a character stamped late, a note between):
    the places are looked for in time order, as the scan sorted them."""
    control = _control(0.0, 1e-3, 12e-3)
    note = Event(EventKind.NOTE, TOOL, 0.0, 0.0, text="a note")
    for events in (control[::-1], [control[0], note, *control[1:]], control[2:] + control[:2]):
        assert unbroken_acknowledge_answered(events, "0", FIRST_CHAR)
        assert _reference(events, "0", FIRST_CHAR)
