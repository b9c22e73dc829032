"""``validity._ascii_problem`` reads a reply's parity and text from its wire bytes (issue 22,
matrix14): every frame's parity in one ``bytes.translate`` and the text from the same bytes
where every event is a character, instead of an ``Event.parity_ok`` call and a decode step
per character. Its answer is the one the character-by-character reading gives (kept below
word for word) for replies with parity errors, wires that are no byte, events that are no
character, gaps past the limit, multi-line text, any command and CRC expectation."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.protocol.commands import Kind, parse_command
from conformance.protocol.crc import ASCII_CRC_LEN
from conformance.protocol.framing import CRLF, LF, unprintable
from conformance.tool_recorder import validity
from conformance.transcript import DUT, Event, EventKind, decode_7e1, escape, to_wire_7e1

COMMANDS = [None, *map(parse_command, ["0D0!", "0M!", "0!", "0I!", "0A1!", "0XHELP!", "0R0!"])]
TEXTS = ["0+1\r\n", "00011\r\n", "0\r\n", "0+1.5Ab\x7f\r\n", "1+2\r\n", "0\x02a\r\nb\r\n\x03", ""]
CHAR = 8.333e-3


def _old_ascii_problem(command, events, address, command_end, gap_limit, crc_expected, multiline):
    """validity._ascii_problem before matrix14, word for word."""
    if events and events[0].start < command_end:
        return "bus contention (reply started during the command)"
    bad = next((i for i, e in enumerate(events) if not e.parity_ok), None)
    if bad is not None:
        return f"parity error in character {bad + 1}"
    for i in range(1, len(events)):
        if multiline and events[i - 1].char7 == LF:
            continue
        gap = events[i].start - events[i - 1].end
        if gap > gap_limit:
            return f"{gap * 1e3:.2f} ms of marking inside the reply"
    text = decode_7e1(events)
    if multiline:
        return validity._text_problem(text, address if command is None else command.address)
    if not text.endswith(CRLF):
        return "no CR LF at the end"
    body = text[:-2]
    if not body:
        return "no address"
    crc_due = crc_expected or (crc_expected is None and len(body) > ASCII_CRC_LEN)
    if unprintable(body, ASCII_CRC_LEN if crc_due else 0):
        return "non-printable character in the reply"
    expected = validity._reply_address(command) if command is not None else address
    if command is not None and command.kind is Kind.CHANGE_ADDRESS and body[0] == command.address:
        expected = command.address
    if expected is None and body[0] not in validity.ADDRESS_CHARS:
        return f"{escape(body[0])} is not an address character"
    if expected is not None and body[0] != expected:
        return f"reply from address {escape(body[0])}, expected {escape(expected)}"
    return validity._shape_problem(command, body, crc_expected) if command is not None else None


#: how one character goes wrong, if it does: its parity bit flipped, a wire past a byte,
#: a break or note in its place, marking before it
spoils = st.sampled_from(["", "", "", "", "parity", "wide", "break", "note", "gap"])


@st.composite
def replies(draw):
    text = draw(st.sampled_from(TEXTS))
    start = draw(st.sampled_from([0.02, 0.005]))
    events = []
    t = start
    for c in text:
        spoil = draw(spoils)
        if spoil == "gap":
            t += draw(st.sampled_from([0.5e-3, 2e-3, 0.2]))
        wire = to_wire_7e1(ord(c))
        kind = EventKind.CHAR
        if spoil == "parity":
            wire ^= 0x80
        elif spoil == "wide":
            wire |= 0x100
        elif spoil == "break":
            kind, wire = EventKind.BREAK, 0
        elif spoil == "note":
            kind = EventKind.NOTE
        events.append(Event(kind, DUT, t, t + CHAR, wire))
        t += CHAR
    return events


@settings(max_examples=1500, deadline=None)
@given(
    st.sampled_from(COMMANDS),
    replies(),
    st.sampled_from(["0", "1"]),
    st.sampled_from([0.009, 0.011]),
    st.sampled_from([0.00873, 0.0104]),
    st.sampled_from([None, True, False]),
    st.booleans(),
)
def test_read_from_wire_bytes_as_character_by_character(
    command, events, address, command_end, gap_limit, crc, multiline
):
    args = (command, events, address, command_end, gap_limit, crc, multiline)
    assert validity._ascii_problem(*args) == _old_ascii_problem(*args)


def test_every_way_out_is_taken():
    """The replies drawn above reach a parity error, a gap, a bad text and an accepted one,
    on the byte path and the event-by-event one (a wire past a byte, a break among them)."""
    reply = [Event(EventKind.CHAR, DUT, 0.02 + i * CHAR, 0.02 + (i + 1) * CHAR, to_wire_7e1(ord(c)))
             for i, c in enumerate("0+1\r\n")]  # fmt: skip
    command = parse_command("0D0!")
    args = ("0", 0.009, 0.00873, False, False)
    assert validity._ascii_problem(command, reply, *args) is None
    flipped = [
        *reply[:2],
        Event(EventKind.CHAR, DUT, reply[2].start, reply[2].end, to_wire_7e1(0x31) ^ 0x80),
    ]
    assert validity._ascii_problem(command, flipped + reply[3:], *args) == (
        "parity error in character 3"
    )
    wide = [*reply[:2], Event(EventKind.CHAR, DUT, reply[2].start, reply[2].end, 0x131)]
    assert validity._ascii_problem(command, wide + reply[3:], *args) == (
        _old_ascii_problem(command, wide + reply[3:], *args)
    )
    brk = [*reply[:2], Event(EventKind.BREAK, DUT, reply[2].start, reply[2].end), *reply[3:]]
    # the break read as no character: '0+' then CR LF, a text the D reply's shape refuses
    assert validity._ascii_problem(command, brk, *args) == _old_ascii_problem(command, brk, *args)
    assert validity._chars_text(brk, b"".join(bytes([e.wire]) for e in brk)) == "0+\r\n"
