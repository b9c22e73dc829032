"""Whether a reply the recorder under test got was valid (section 7.2), decided by the judges.

A recorder is judged on whether it retried an invalid reply and took a valid one, so the
judges need a validity rule. It must not be the golden recorder's own
(:mod:`conformance.tool_recorder.validity`): a judge that shares the decision code of the reference
it is compared with cannot catch that reference's mistakes, and a bug there would pass both.
So the rules here rest on the response grammar of :mod:`conformance.protocol.responses` and
:mod:`conformance.protocol.binary`, and every problem carries a :class:`Reason` code: judges
test the code, never the wording of a message.

Loose on purpose, as a recorder's test must be: a problem is what makes a reply unusable
(nothing came, contention, parity, a pause inside it, no CR LF, a non-printable character,
the wrong address, a shape the command does not allow, a CRC missing, wrong or unasked).
A value spelled oddly or a field too long is a finding on the sensor, not a reason to ask
again.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from ..protocol.binary import parse_binary_packet
from ..protocol.commands import Command, Kind
from ..protocol.crc import is_crc_char
from ..protocol.framing import CRLF, ETX, STX
from ..protocol.responses import (
    check_address,
    parse_data_reply,
    parse_ident,
    parse_measurement_reply_for,
    parse_metadata_reply,
    split_line,
)
from ..protocol.values import Violation
from ..transcript import Event, decode_7e1, decode_8n1, escape

NO_LIMIT = 10**6  # value-length limits are the sensor's findings, not validity

#: Violations of these rules mean a wrong CRC (value or encoding).
_CRC_WRONG = frozenset({"R-4.4.12-05", "R-4.4.12-06", "R-5.2-03"})
#: ...a CRC that is due but absent (D/R replies; the HA limit rule doubles as its CRC rule).
_CRC_MISSING = frozenset({"R-4.4.12-02"})
_CRC_UNASKED = frozenset({"R-4.4.12-03"})
_ADDRESS = frozenset({"R-4.3-01", "R-4.3-04"})


class Reason(StrEnum):
    """Why a reply is invalid; the codes judges compare, whatever the message says."""

    NO_REPLY = "no-reply"
    CONTENTION = "contention"
    PARITY = "parity"
    PAUSE = "pause"
    FRAMING = "framing"
    ADDRESS = "address"
    SHAPE = "shape"
    CRC_MISSING = "crc-missing"
    CRC_WRONG = "crc-wrong"
    CRC_UNASKED = "crc-unasked"
    PACKET = "packet"
    #: not the sensor's: the recorder's own break cut into the reply while it was coming
    CUT = "cut-by-recorder"


@dataclass(frozen=True)
class ReplyProblem:
    """One reason a reply is invalid, with a line for the reader."""

    reason: Reason
    detail: str

    def __str__(self) -> str:
        return self.detail


NO_REPLY = ReplyProblem(Reason.NO_REPLY, "no reply")


def check_reply(
    command: Command | None,
    events: list[Event],
    *,
    address: str,
    command_end: float,
    gap_limit: float,
    crc_expected: bool | None,
) -> ReplyProblem | None:
    """Why the 7E1 reply ``events`` to ``command`` is invalid, or None.

    ``address``: the addressee, for a transmission that is no parsable command.
    ``crc_expected``: whether a D reply carries a CRC (None: not known, judged by its look).
    """
    if not events:
        return NO_REPLY
    timing = _timing_problem(events, command_end, gap_limit)
    if timing is not None:
        return timing
    text = decode_7e1(events)
    if len(text) > 1 and ord(text[1]) == STX:
        return _text_problem(text, address)
    crc = _crc_due(command, text, crc_expected)
    body, framing = split_line(text, crc_positions=3 if crc else 0)
    if framing:
        return ReplyProblem(Reason.FRAMING, framing[0].message)
    if command is None:
        bad = check_address(body, address)
        return _first(bad, Reason.ADDRESS)
    wrong = check_address(body, _reply_address(command, body))
    if wrong:
        return _first(wrong, Reason.ADDRESS)
    return _shape_problem(command, body, crc)


def check_packet(events: list[Event], *, address: str, command_end: float) -> ReplyProblem | None:
    """Why the 8N1 ``aDBn!`` reply ``events`` is invalid, or None."""
    if not events:
        return NO_REPLY
    if events[0].start < command_end:
        return ReplyProblem(Reason.CONTENTION, "bus contention (reply started during the command)")
    packet = parse_binary_packet(decode_8n1(events), expected_address=address)
    hard = [v for v in packet.violations if not v.warning]
    crc = [v for v in hard if v.requirement in _CRC_WRONG]
    if crc:
        return ReplyProblem(Reason.CRC_WRONG, crc[0].message)
    return _first(hard, Reason.PACKET)


def _timing_problem(
    events: list[Event], command_end: float, gap_limit: float
) -> ReplyProblem | None:
    if events[0].start < command_end:
        return ReplyProblem(Reason.CONTENTION, "bus contention (reply started during the command)")
    bad = next((i for i, e in enumerate(events) if not e.parity_ok), None)
    if bad is not None:
        return ReplyProblem(Reason.PARITY, f"parity error in character {bad + 1}")
    multiline = len(events) > 1 and events[1].char7 == STX
    for a, b in zip(events, events[1:], strict=False):
        if multiline and a.char7 == 0x0A:
            continue  # between the lines of a text: up to 150 ms, judged elsewhere
        if b.start - a.end > gap_limit:
            return ReplyProblem(
                Reason.PAUSE, f"{(b.start - a.end) * 1e3:.2f} ms of marking inside the reply"
            )
    return None


def _text_problem(text: str, address: str) -> ReplyProblem | None:
    """Multi-line text ``a<STX>line<CR><LF>...[<ETX>]``: an ETX that never came is no reason
    to ask again (the text ends 150 ms after its last line, R-4.4.13.1-04)."""
    body = text[:-1] if text.endswith(CRLF + chr(ETX)) else text
    if not body.endswith(CRLF):
        return ReplyProblem(Reason.FRAMING, "multi-line text does not end in CR LF")
    wrong = check_address(body[:1], address)
    if wrong:
        return _first(wrong, Reason.ADDRESS)
    for line in body[2:-2].split(CRLF):
        _, framing = split_line(line + CRLF)
        printable = [v for v in framing if v.requirement == "R-4.2-02"]
        if printable:
            return ReplyProblem(Reason.FRAMING, printable[0].message)
    return None


def _crc_due(command: Command | None, text: str, crc_expected: bool | None) -> bool:
    """Whether a CRC belongs on this reply (to exempt 0x7F in it from the printable rule)."""
    if command is None:
        return False
    if command.kind is Kind.CONTINUOUS:
        return command.crc
    if command.kind is Kind.METADATA and command.target is not None:
        return command.target.returns_crc
    if command.kind is Kind.DATA:
        if crc_expected is None:
            body = text[:-2] if text.endswith(CRLF) else text
            return len(body) >= 4 and all(is_crc_char(c) for c in body[-3:])
        return crc_expected
    return False


def _reply_address(command: Command, body: str) -> str | None:
    """The address the reply must carry: any for ``?!``; the new one (or, refused, the old
    one) for ``aAb!``; the addressee otherwise."""
    if command.kind is Kind.QUERY_ADDRESS:
        return None
    if command.kind is Kind.CHANGE_ADDRESS:
        return command.address if body[:1] == command.address else command.new_address
    return command.address


def _shape_problem(command: Command, body: str, crc: bool) -> ReplyProblem | None:
    """The reply's shape for the command family, from the response grammar."""
    kind = command.kind
    if kind in (Kind.ACKNOWLEDGE, Kind.QUERY_ADDRESS, Kind.CHANGE_ADDRESS):
        if len(body) != 1:
            return ReplyProblem(Reason.SHAPE, f"'{escape(body)}' is not the address alone")
        return None
    if kind is Kind.IDENTIFY:
        version = parse_ident(body).version
        if not (len(version) == 2 and version.isdigit()):
            return ReplyProblem(Reason.SHAPE, "no 2-digit version after the address")
        return None
    if command.starts_measurement or kind is Kind.IDENTIFY_MEASUREMENT:
        reply = parse_measurement_reply_for(body, command)
        return _first(_hard(reply.violations, exclude=_ADDRESS), Reason.SHAPE)
    if kind in (Kind.DATA, Kind.CONTINUOUS):
        reply = parse_data_reply(body, crc_expected=crc, limit=NO_LIMIT)
        return _crc_or_shape(_hard(reply.violations, exclude=_ADDRESS))
    if kind is Kind.METADATA:
        reply = parse_metadata_reply(body, crc_expected=crc)
        found = [
            v
            for v in _hard(reply.violations, exclude=_ADDRESS)
            if v.requirement in _CRC_WRONG or v.requirement in ("R-6.2-02", "R-6.2-05")
        ]
        return _crc_or_shape(found)
    return None  # extended commands: the address and CR LF are all the standard fixes


def _crc_or_shape(found: list[Violation]) -> ReplyProblem | None:
    for ids, reason in (
        (_CRC_WRONG, Reason.CRC_WRONG),
        (_CRC_MISSING, Reason.CRC_MISSING),
        (_CRC_UNASKED, Reason.CRC_UNASKED),
    ):
        hit = [v for v in found if v.requirement in ids]
        if hit:
            return ReplyProblem(reason, hit[0].message)
    return _first(found, Reason.SHAPE)


def _hard(violations: list[Violation], *, exclude: frozenset[str]) -> list[Violation]:
    """The violations that make a reply unusable: errors, not warnings."""
    return [v for v in violations if not v.warning and v.requirement not in exclude]


def _first(violations: list[Violation], reason: Reason) -> ReplyProblem | None:
    return ReplyProblem(reason, violations[0].message) if violations else None
