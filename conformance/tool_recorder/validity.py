"""The engine's own, deliberately loose, idea of a "valid reply" (section 7.2).

A recorder must retry on an invalid reply (bad format, parity, framing, CRC, contention,
R-7.2-05) and stop retrying once a valid one is in. That decision needs a validity test, but
it is *not* the conformance verdict: judges apply the full response grammar with requirement
IDs. Here a reply only has to be recognisably the answer to the command (address, CR LF,
parity, CRC where one is due, the rough shape of the reply) so that the engine neither
retries a merely imperfect reply nor accepts garbage as data.
"""

from __future__ import annotations

import re

from ..protocol.binary import EMPTY_LEN, DataType, packet_length, type_size
from ..protocol.commands import ADDRESS_CHARS, Command, Kind, count_digits
from ..protocol.crc import ASCII_CRC_LEN, CRC_CHAR, ascii_crc, binary_crc
from ..protocol.framing import CR, CRLF, LF, TEXT_END, crc_tail, strip_crlf, unprintable
from ..transcript import (
    GOOD_PARITY,
    SEVEN_BITS,
    Event,
    EventKind,
    decode_7e1,
    decode_8n1,
    escape,
    wire_bytes,
)

_TYPE_CODES = frozenset(int(t) for t in DataType)  # R-5.2.1-01: codes above 10 are invalid
_VALUES = re.compile(r"([+-][0-9.]+)*")
_CHAR = EventKind.CHAR
#: the command kinds a reply's check asks about, as module constants: a member read off the
#: enum on Python 3.11 goes through its metaclass's ``__getattr__`` hook (issue 22, matrix25:
#: ~0.13 us a look, a dozen looks a metadata reply's check)
_QUERY_ADDRESS, _CHANGE_ADDRESS, _IDENTIFY = Kind.QUERY_ADDRESS, Kind.CHANGE_ADDRESS, Kind.IDENTIFY
_IDENTIFY_MEASUREMENT, _METADATA = Kind.IDENTIFY_MEASUREMENT, Kind.METADATA
_CONTINUOUS = Kind.CONTINUOUS
_ADDRESS_ONLY = (Kind.ACKNOWLEDGE, Kind.QUERY_ADDRESS, Kind.CHANGE_ADDRESS)
_VALUE_REPLIES = (Kind.DATA, Kind.CONTINUOUS)

__all__ = [
    "check_ascii",
    "check_packet",
    "count_digits",  # the protocol's count-digit table, for the engine and the bus clock
    "data_values_text",
    "ends_line",
    "packet_value_count",
    "parse_start_reply",
    "reads_past_packet",
    "split_crc",
]


def parse_start_reply(text: str, digits: int) -> tuple[int, int] | None:
    """``(ttt, count)`` from ``atttn<CR><LF>`` (or nn/nnn); None if it is not that shape."""
    m = re.fullmatch(rf".([0-9]{{3}})([0-9]{{{digits}}})\r\n", text, flags=re.DOTALL)
    return (int(m[1]), int(m[2])) if m else None


def ends_line(events: list[Event]) -> bool:
    """The characters so far end in CR LF (7-bit, parity ignored): ``framing.ends_line`` of
    their codes, read off the last two events (asked after every character a reply brings)."""
    return len(events) >= 2 and events[-2].wire & 0x7F == CR and events[-1].wire & 0x7F == LF


def packet_value_count(data: bytes) -> int:
    """Values inside a complete packet: payload size over the type's size (0 if unusable)."""
    length = packet_length(data)
    if length is None or len(data) < length or data[3] not in _TYPE_CODES:
        return 0
    size = type_size(data[3])
    return (length - EMPTY_LEN) // size if size else 0


def reads_past_packet(packets: list[bytes], count: int) -> bool:
    """Whether an observer (a salvaging recorder) reads on past the last of ``packets``, a DB
    packet that held no values: unless it is the empty packet (a size field of 0, either
    byte order), the same packet as the one before (the sensor is not advancing), or as
    many packets are in as the measurement announced values (each holds one at least).
    An unreadable packet (a size field that does not fit, an unknown type) ended the
    collection, so the packets after it were never asked: R-5.2-04 PASSed on aDB0! alone
    beside a 1002-byte DB10 (binary-size-big-endian + binary-payload-over-1000)."""
    last = packets[-1]
    if len(last) < EMPTY_LEN or last[1:3] == b"\x00\x00":
        return False
    if len(packets) >= 2 and packets[-2] == last:
        return False
    return len(packets) < count


def split_crc(body: str, crc_expected: bool | None) -> tuple[str, str | None]:
    """Cut a trailing 3-character CRC off ``body`` (address + values [+ CRC]).

    ``crc_expected`` None means "not known" (a D command sent on its own): a CRC is then
    taken off only if the last three characters can only be CRC characters.
    """
    tail = body[-ASCII_CRC_LEN:]
    if crc_expected or (crc_expected is None and crc_tail(body)):
        return body[:-ASCII_CRC_LEN], tail
    return body, None


def data_values_text(reply: str, crc_expected: bool | None) -> str:
    """The ``<values>`` part of a D/R reply: address, CRC and CR LF removed."""
    return split_crc(strip_crlf(reply), crc_expected)[0][1:]


#: Every character an ASCII CRC is made of (0x40..0x7F); no value character is one.
CRC_CHARS = "".join(map(chr, range(0x40, 0x80)))


def salvaged_values_text(values: str) -> str:
    """What the ``<values>`` part of a D reply that was not accepted still reads as values
    (an observer's salvage): a stray or unexpected CRC's characters and spaces cut off."""
    return values.rstrip(CRC_CHARS).strip()


def _reply_address(command: Command) -> str | None:
    """The address the reply must start with; None means any address character."""
    if command.kind is _QUERY_ADDRESS:
        return None
    if command.kind is _CHANGE_ADDRESS:
        return command.new_address
    return command.address


def _crc_problem(body: str, crc_expected: bool | None) -> str | None:
    checked, crc = split_crc(body, crc_expected)
    if crc is None:
        if crc_expected is False and CRC_CHAR.search(body, 1) is not None:
            return "unexpected CRC characters"
        return None
    if len(body) <= ASCII_CRC_LEN:
        return "missing CRC"
    if crc != ascii_crc(checked):
        return f"CRC '{escape(crc)}' should be '{escape(ascii_crc(checked))}'"
    return None


def _shape_problem(command: Command, body: str, crc_expected: bool | None) -> str | None:
    """Loose reply shape per command family (the full grammar is the judges' business)."""
    kind, rest = command.kind, body[1:]
    if kind in _ADDRESS_ONLY:
        return None if rest == "" else "expected the address alone"
    if kind is _IDENTIFY:
        return None if re.match(r"[0-9]{2}", rest) else "no 2-digit version after the address"
    if command.starts_measurement or kind is _IDENTIFY_MEASUREMENT:
        digits = 3 + count_digits(command)
        return (
            None
            if re.fullmatch(rf"[0-9]{{{digits}}}", rest)
            else f"not {digits} digits after the address"
        )
    if kind in _VALUE_REPLIES:
        crc = command.crc if kind is _CONTINUOUS else crc_expected
        problem = _crc_problem(body, crc)
        if problem:
            return problem
        if not _VALUES.fullmatch(split_crc(body, crc)[0][1:]):
            return "values are not sign-separated numbers"
        return None
    if kind is _METADATA:
        assert command.target is not None
        crc = command.target.returns_crc
        problem = _crc_problem(body, crc) if crc else None  # fields may hold any letters
        if problem:
            return problem
        fields = split_crc(body, crc)[0][1:]
        ok = fields == "" or (fields.startswith(",") and fields.endswith(";"))
        return None if ok else "not ',field,...;'"
    return None  # extended commands: address and CR LF are all the standard fixes


def fits_shape(command: Command, text: str) -> bool:
    """Whether the line ``text`` is loosely a reply to ``command``: its address and the shape
    of its family as the engine accepts it (:func:`_shape_problem`), a CRC's value aside (a
    D or R reply's CRC is cut where it reads as one). Which of two commands a reply that
    began after both answers is decided by its words (judges.late_before)."""
    body = strip_crlf(text)
    if not text.endswith(CRLF) or not body:
        return False
    expected = _reply_address(command)
    if expected is not None and body[0] != expected:
        return False
    crc: bool | None = None
    if command.kind in _VALUE_REPLIES:
        body, crc = split_crc(body, None)[0], False
    return _shape_problem(command, body, crc) is None


#: the replies :func:`check_ascii` judged last, by what it was asked (the command by its
#: ``id``): (that command, the events, why)
_JUDGED: dict[tuple[object, ...], tuple[Command | None, list[Event], str | None]] = {}
_JUDGED_MAX = 64  # cleared when full: the tool recorder's attempts of a stimulus or two


def check_ascii(
    command: Command | None,
    events: list[Event],
    *,
    address: str,
    command_end: float,
    gap_limit: float,
    crc_expected: bool | None = None,
    multiline: bool = False,
    text: str | None = None,
) -> str | None:
    """Why a finished 7E1 reply is invalid (R-7.2-05), or None if the engine accepts it.

    ``address`` is used when the command could not be parsed (raw probes). ``multiline``:
    an ``a<STX>...<CR><LF><ETX>`` text, where the pauses between lines are allowed.
    ``text``: ``decode_7e1(events)`` where the caller has it already (the engine decodes
    a reply once and carries the text with it, :attr:`Attempt.reply_text`).

    A pure function of its arguments, asked twice about nearly every reply of a sensor run:
    by the tool recorder as it reads the reply, then by the view's records of the stimulus
    (``view.rebuilt_records``), the same characters with the same command, so the answers
    to the last few questions are kept (the events compared, not only their number). The
    command is known by its identity (both ask with the object :func:`parse_command` keeps
    for the text): a frozen dataclass's hash is worked out anew at every look, a metadata
    command's with its target's, three times a reply (matrix21); an equal command made
    apart is only a question asked afresh, and the command kept with the answer is the one
    asked about (an ``id`` may be reused once its object is gone).
    """
    key = (id(command), address, command_end, gap_limit, crc_expected, multiline, len(events))
    kept = _JUDGED.get(key)
    if kept is not None and kept[0] is command and kept[1] == events:
        return kept[2]
    why = _ascii_problem(
        command, events, address, command_end, gap_limit, crc_expected, multiline, text
    )
    if len(_JUDGED) >= _JUDGED_MAX:
        _JUDGED.clear()
    _JUDGED[key] = (command, list(events), why)
    return why


def _ascii_problem(
    command: Command | None,
    events: list[Event],
    address: str,
    command_end: float,
    gap_limit: float,
    crc_expected: bool | None,
    multiline: bool,
    text: str | None = None,
) -> str | None:
    """:func:`check_ascii`, worked out."""
    if events and events[0].start < command_end:
        return "bus contention (reply started during the command)"
    wires = wire_bytes(events)
    # every frame's parity in one C pass where each wire is a byte (GOOD_PARITY: the wire
    # bits of the 7E1 characters whose parity holds); the first bad one found as before
    if wires is None or wires.translate(None, GOOD_PARITY):
        bad = next((i for i, e in enumerate(events) if not e.parity_ok), None)
        if bad is not None:
            return f"parity error in character {bad + 1}"
    for i in range(1, len(events)):
        if multiline and events[i - 1].char7 == LF:
            continue  # between lines: up to 150 ms (R-4.4.13.1-03), judged elsewhere
        gap = events[i].start - events[i - 1].end
        if gap > gap_limit:
            return f"{gap * 1e3:.2f} ms of marking inside the reply"
    # the text: those wire bytes' seven bits where every event is a character (a reply
    # nearly always), else decoded character by character
    if text is None:
        text = _chars_text(events, wires)
    if multiline:
        return _text_problem(text, address if command is None else command.address)
    if not text.endswith(CRLF):
        return "no CR LF at the end"
    body = text[:-2]
    if not body:
        return "no address"
    crc_due = crc_expected or (crc_expected is None and len(body) > ASCII_CRC_LEN)
    if unprintable(body, ASCII_CRC_LEN if crc_due else 0):
        return "non-printable character in the reply"
    expected = _reply_address(command) if command is not None else address
    if command is not None and command.kind is _CHANGE_ADDRESS and body[0] == command.address:
        expected = command.address  # aAb! refused: the old address is a valid reply too
    if expected is None and body[0] not in ADDRESS_CHARS:
        return f"{escape(body[0])} is not an address character"
    if expected is not None and body[0] != expected:
        return f"reply from address {escape(body[0])}, expected {escape(expected)}"
    return _shape_problem(command, body, crc_expected) if command is not None else None


def _chars_text(events: list[Event], wires: bytes | None) -> str:
    """``decode_7e1(events)`` read from their ``wires`` (:func:`wire_bytes`) where every
    event is a character: the text of a reply's frames, parity stripped."""
    if wires is not None:
        for e in events:  # (a plain loop: all() over a generator costs twice as much)
            if e.kind is not _CHAR:
                break
        else:
            return wires.translate(SEVEN_BITS).decode("ascii")
    return decode_7e1(events)


def _text_problem(text: str, address: str) -> str | None:
    """A multi-line text: address, STX, lines ending CR LF, ETX after the last one.

    A text whose ETX never came is still accepted once 150 ms passed after a complete line:
    the recorder then concludes that no more lines follow (R-4.4.13.1-04); the missing ETX is
    the judges' finding, not a reason to ask again.
    """
    body = text[:-1] if text.endswith(TEXT_END) else text
    if not body.endswith(CRLF):
        return "multi-line text does not end in CR LF"
    if text[0] != address:
        return f"reply from address {escape(text[0])}, expected {escape(address)}"
    lines = body[2:-2].split(CRLF)
    if any(unprintable(line) for line in lines):
        return "non-printable character in the text"
    return None


def check_packet(events: list[Event], *, address: str, command_end: float) -> str | None:
    """Why a finished 8N1 ``aDBn!`` reply is invalid, or None (R-5.2-02/03, R-5.2-08)."""
    if events and events[0].start < command_end:
        return "bus contention (reply started during the command)"
    data = decode_8n1(events)
    length = packet_length(data)
    if length is None or len(data) < length:
        return f"packet cut short after {len(data)} bytes"
    if len(data) > length:
        return f"{len(data) - length} bytes after the packet"
    if chr(data[0]) != address:
        return f"packet from address {escape(data[:1])}, expected {escape(address)}"
    if data[3] not in _TYPE_CODES:
        return f"data type {data[3]} is not defined"
    if binary_crc(data[:-2]) != data[-2:]:
        return "binary CRC mismatch"
    return None
