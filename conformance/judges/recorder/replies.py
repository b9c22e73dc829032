"""Whether the sensor's reply to each transmission of the recorder under test was valid, by
the judges' own rules (:mod:`conformance.judges.reply_validity`), and what a valid data reply
held. Retry and measurement reconstruction both start from these decisions."""

from __future__ import annotations

from ...protocol.commands import Command
from ...protocol.framing import ETX, LF
from ...protocol.responses import parse_data_reply, split_line
from ...protocol.timing import CHAR_TIME, TOLERANCE
from ...transcript import decode_7e1, escape
from ...view.segments import TranscriptView, Transmission
from ..reply_validity import NO_LIMIT, Reason, ReplyProblem, check_packet, check_reply


def reply_problem(
    sent: Transmission, crc_expected: bool | None, uncertainty: float
) -> ReplyProblem | None:
    """Why the sensor's reply to ``sent`` was not a valid reply (:data:`NO_REPLY` if none
    came), by the judges' own rules (:mod:`.reply_validity`), not the golden recorder's. A
    reply the recorder's own break cut into (:attr:`Transmission.cut_by`) is
    :data:`Reason.CUT`: what was heard of it is no invalid reply of the sensor's."""
    cut = cut_off(sent)
    if cut is not None:
        return cut
    if sent.binary:
        return check_packet(sent.reply, address=sent.address, command_end=sent.end)
    return check_reply(
        sent.command,
        sent.reply,
        address=sent.address,
        command_end=sent.end,
        gap_limit=CHAR_TIME + TOLERANCE + uncertainty,
        crc_expected=crc_expected,
    )


def cut_off(sent: Transmission) -> ReplyProblem | None:
    """:data:`Reason.CUT` where the recorder's own break began while the reply to ``sent``
    was still coming (its framed reply ends with the last character heard, no LF or ETX)."""
    brk = sent.cut_by
    if brk is None or sent.binary:
        return None
    reply = sent.reply
    if not reply or reply[-1] is not sent.heard[-1] or reply[-1].char7 in (LF, ETX):
        return None
    return ReplyProblem(
        Reason.CUT,
        f"the recorder's break at t={brk.start:.3f} s cut into the reply "
        f"'{escape(decode_7e1(reply))}' while the sensor was still sending it",
    )


def crc_context(
    line: TranscriptView, pending: dict[str, bool] | None = None
) -> dict[int, bool | None]:
    """For each transmission index: whether its reply carries a CRC (D after MC, CC, HA...).
    ``pending``: whether each address's last measurement asked for one, as the windows
    before ``line`` left it (a data reply read long after its measurement is judged by it);
    updated in place, so a windowed judge carries it to the next window (None: none
    before)."""
    pending = {} if pending is None else pending
    result: dict[int, bool | None] = {}
    for i, s in enumerate(line.transmissions):
        cmd = s.command
        if cmd is not None and cmd.starts_measurement:
            pending[cmd.address] = cmd.returns_crc
        result[i] = pending.get(s.address) if s.data_index is not None else None
    return result


def data_values(sent: Transmission, measurement: Command) -> list[str]:
    """The values of a valid D reply to ``sent`` after ``measurement`` (its CRC taken off)."""
    body, _ = split_line(decode_7e1(sent.reply))
    return parse_data_reply(body, crc_expected=measurement.returns_crc, limit=NO_LIMIT).values


def first_answered(line: TranscriptView, uncertainty: float) -> dict[str, Transmission]:
    """For each transmitted text, its first transmission that drew a valid reply (one pass:
    a field recording holds tens of thousands of transmissions)."""
    crc = crc_context(line)
    found: dict[str, Transmission] = {}
    for i, s in enumerate(line.transmissions):
        text = s.text
        if text not in found and reply_problem(s, crc[i], uncertainty) is None:
            found[text] = s
    return found
