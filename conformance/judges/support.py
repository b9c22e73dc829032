"""Whether the sensor serves a command, read from a well-formed answer of that command's
kind only (issue 18).

Real firmware answers what it does not understand with text of its own (``5UNKN``), and
some answers ``aC!`` with ``a00000``. Neither is support: a reply longer than the address is
not yet values, and a start reply that announces nothing starts no measurement. Every case
that asks "is this served?" asks here, so one error text cannot switch a feature on in one
case while another calls it unsupported.
"""

from __future__ import annotations

from ..protocol.binary import parse_binary_packet
from ..protocol.crc import is_crc_char
from ..protocol.responses import parse_measurement_reply_for, split_line
from ..protocol.values import check_value, split_values
from ..tool_recorder.records import Exchange, Measurement

SIGNS = "+-"


def values_of(ex: Exchange) -> list[str]:
    """The well-formed values of an R/RC/D reply: the text after the address, without a
    CRC, cut at the signs; empty when the reply has none or is not values at all."""
    if not ex.answered:
        return []
    body, _ = split_line(ex.reply_text)
    rest = body[1:]
    start = next((i for i, c in enumerate(rest) if c in SIGNS), None)
    if start != 0:
        return []  # nothing, or text before the first sign: not a values reply
    end = len(rest)
    while end > 0 and 0x40 <= ord(rest[end - 1]) <= 0x7F:
        end -= 1  # a CRC, which values never contain
    values = split_values(rest[:end])
    return values if all(not check_value(v) for v in values) else []


def serves_continuous(ex: Exchange) -> bool:
    """An ``aRn!`` is served only when its reply carries at least one well-formed value."""
    return bool(values_of(ex))


def text_instead_of_values(ex: Exchange, crc: bool = False) -> bool:
    """A reply that is neither values nor the empty form (``a`` or ``a<CRC>``): the text a
    firmware sends to what it does not serve, on which no value or CRC format can be judged."""
    if not ex.answered:
        return False
    body, _ = split_line(ex.reply_text)
    rest = body[1:]
    if not rest or any(c in SIGNS for c in rest):
        return False
    return not (crc and len(rest) == 3)


def serves_measurement(m: Measurement) -> bool:
    """A measurement command is served when its start reply is well formed and announces
    at least one value (``a00000`` to ``aC!`` starts no measurement, R-4.4.7-02)."""
    return m.start.answered and m.count is not None and m.count > 0 and m.ttt is not None


def text_instead_of_start(m: Measurement) -> bool:
    """A start reply with no digit after the address (``aUNKN``, or the bare ``a`` of an
    a! answer): no atttn(n) tried, so no measurement started and the command is not served,
    however its form is judged (joembedded's SDI_12_slave answered aC! '0UNKN', docs/kit.md)."""
    if not m.start.answered:
        return False
    rest = split_line(m.start.reply_text)[0][1:]
    return not any(c.isdigit() for c in rest)


def unreadable_count(m: Measurement) -> bool:
    """The start reply answered in digits that give no count (``0023`` to ``aM!``: a ttt of
    two digits), so no D command followed it: values the sensor may hold there were never
    read. A reply of zeros only announces no values however it is read (``a000`` to an
    undefined ``aMn!``), and text (``aUNKN``) is no measurement reply: neither hides values."""
    if not m.start.answered or m.count is not None:
        return False
    rest = split_line(m.start.reply_text)[0][1:]
    return rest.isdigit() and set(rest) != {"0"}


def first_filled(m: Measurement) -> int:
    """The index of the first of ``m``'s D replies that held values (a sign past its
    address), 0 if none did. A sensor whose groups start later answers the D commands
    before it with no values whatever its buffer holds, so a probe for values left in the
    buffer reads up to this one (groups-start-at-d1 hid the old data an undefined aMn!
    and an abort left behind: seeds 4064, 4066)."""
    for i, ex in enumerate(m.data):
        if ex.answered and any(c in SIGNS for c in split_line(ex.reply_text)[0][1:]):
            return i
    return 0


def empty_data_reply(ex: Exchange) -> bool:
    """A D reply with no values: ``a`` or ``a<CRC>`` before the CR LF (its address and CRC
    are judged by their own rules): what a sensor must give after an abort (R-4.4.5.1-02,
    R-4.4.7.1-02)."""
    rest = split_line(ex.reply_text)[0][1:]
    return rest == "" or (len(rest) == 3 and all(map(is_crc_char, rest)))


def holds_values(ex: Exchange, binary: bool = False) -> bool:
    """An answered D reply with more than its address and CRC, or with ``binary`` a DB packet
    with a payload: what a buffer that kept values gives (the control read before an abort,
    :meth:`SensorSession.values_after_standby`)."""
    if not ex.answered:
        return False
    if binary:
        return parse_binary_packet(ex.reply_bytes).size > 0
    return not empty_data_reply(ex)


def announced_ttt(ex: Exchange) -> int | None:
    """The ttt the start reply ``ex`` took announces, read as the command's ``atttn``-type
    reply (None where it gives none: no reply, text, or digits that do not read as one).
    A rule on what follows a ttt (R-4.4.6-03: no service request after ttt = 000) holds the
    sensor to the reply it gave this time, not to one an earlier run of the command gave:
    replies-after-retry beside service-request-after-ttt-zero took the request '0<CR><LF>'
    for 0M1!'s reply, and "no service request in 0.5 s after 0M1! -> '0<CR><LF>'" PASSed
    R-4.4.6-03 on a sensor that sends one (truth19)."""
    if not ex.answered or ex.command is None:
        return None
    body = split_line(ex.reply_text)[0]
    return parse_measurement_reply_for(body, ex.command, expected_address=ex.command.address).ttt
