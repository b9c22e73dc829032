"""Sans-I/O parsers and validators for every ASCII SDI-12 response.

Each parser takes a reply *body* (the text after :func:`split_line` removed CR LF), never
raises on malformed input, and returns a frozen record with the fields it could recover plus
a list of :class:`Violation`. A judge turns violations into findings; the tool recorder uses
``ok`` to decide whether a reply is valid enough to stop retrying (R-7.2-05).

Every violation names the most specific requirement of requirements.md. Rules that depend on
the command a reply answers (which length limit, whether a CRC is due, whether n = 0 is
allowed) take that context as parameters; the ``*_for`` helpers derive it from a
:class:`~conformance.protocol.commands.Command`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.protocol.commands import (
    ADDRESS_CHARS,
    MEASUREMENT_KINDS,
    Command,
    Kind,
    count_digits,
    described,
)
from conformance.protocol.crc import ASCII_CRC_LEN, crc16, encode_ascii, is_crc_char
from conformance.protocol.framing import CRLF, crc_tail, unprintable
from conformance.protocol.values import (
    VALUES_MAX,
    VALUES_MAX_MEASURE,
    Checked,
    Violation,
    check_value,
    continues_split_value,
    errors,
    split_values,
)
from conformance.protocol.version import V13
from conformance.transcript import escape

__all__ = [
    "Violation",
    "errors",
    "split_line",
    "check_address",
    "check_address_reply",
    "check_change_address_reply",
    "service_request",
    "is_service_request",
    "Identification",
    "parse_ident",
    "MeasurementReply",
    "parse_measurement_reply",
    "parse_measurement_reply_for",
    "measurement_digits",
    "check_measurement_count",
    "DataReply",
    "parse_data_reply",
    "parse_data_reply_for",
    "check_data_sequence",
    "expected_value_limit",
    "MetadataReply",
    "parse_metadata_reply",
    "METADATA_MAX_CHARS",
]

METADATA_MAX_CHARS = 75  # R-6.2-04 / decision A7: address through ';' inclusive
IDENT_MIN, IDENT_MAX = 20, 33  # R-4.4.2-01: a + ll + 8 + 6 + 3 + 0..13


def _digits(text: str, width: int) -> bool:
    """Exactly ``width`` ASCII decimal digits (str.isdigit alone admits other scripts)."""
    return len(text) == width and text.isascii() and text.isdigit()


def _ascii_crc(text: str) -> str:
    """The CRC characters due for ``text``, for untrusted input: characters beyond Latin-1
    (which no 7-bit line carries) become '?' instead of raising as crc.ascii_crc would."""
    return encode_ascii(crc16(text.encode("latin-1", "replace")))


# -- line framing --------------------------------------------------------------------------
def split_line(raw: str, crc_positions: int = 0) -> tuple[str, list[Violation]]:
    """Strip the final CR LF from ``raw`` and check the framing rules every reply shares.

    R-4.2-03: at least three characters and a CR LF at the end. R-4.2-02: everything before
    it printable. CRC characters 2 and 3 may legally be 0x7F, so callers that expect a CRC
    pass ``crc_positions=3`` to exempt 0x7F in the last three body characters. A partial
    terminator (a lone CR or LF at the end) is removed from the body but still reported.
    """
    found: list[Violation] = []
    if raw.endswith(CRLF):
        body = raw[:-2]
        if not body:
            found.append(Violation("R-4.2-03", "reply '<CR><LF>' has no address before CR LF"))
    else:
        body = raw[:-1] if raw.endswith(tuple(CRLF)) else raw
        found.append(Violation("R-4.2-03", f"reply '{escape(raw)}' does not end with CR LF"))
    bad = unprintable(body, crc_positions)
    if bad:
        shown = escape("".join(dict.fromkeys(bad)))
        found.append(
            Violation(
                "R-4.2-02", f"reply '{escape(body)}' contains non-printable characters {shown}"
            )
        )
    return body, found


# -- address checks ------------------------------------------------------------------------
def check_address(body: str, expected: str | None = None) -> list[Violation]:
    """The first character must be a legal address (A17) and, if known, the expected one."""
    if not body:
        return [Violation("R-4.3-01", "reply is empty: no address")]
    first = body[0]
    if first not in ADDRESS_CHARS:
        return [Violation("R-4.3-04", f"reply starts with '{escape(first)}', not an address")]
    if expected is not None and first != expected:
        return [
            Violation(
                "R-4.3-01",
                f"reply starts with address '{escape(first)}', expected '{escape(expected)}'",
            )
        ]
    return []


def check_address_reply(body: str, expected: str | None, requirement: str) -> list[Violation]:
    """Replies that are nothing but an address: ``a!`` (R-4.4.1-01), ``?!`` (R-4.4.3-01),
    ``aAb!`` (R-4.4.4-01). ``expected`` is the address that must come back, if known."""
    found = check_address(body[:1], expected) if body else []
    if len(body) != 1:
        found.append(
            Violation(requirement, f"reply '{escape(body)}' is not a single address character")
        )
    return found


def check_change_address_reply(body: str, old: str, new: str) -> list[Violation]:
    """``aAb!`` answers with the new address, or with the old one if the change failed
    (R-4.4.4-01); whether it really changed is for a follow-up ``?!`` to show."""
    found = check_address_reply(body, None, "R-4.4.4-01")
    if len(body) == 1 and not found and body not in (old, new):
        found.append(
            Violation(
                "R-4.4.4-01",
                f"aAb! reply '{escape(body)}' is neither the new address '{escape(new)}' "
                f"nor the old one '{escape(old)}'",
            )
        )
    return found


def holds_values(reply: str) -> bool:
    """A D reply that holds values: a digit after the address. A value has digits and CRC
    characters never do, so this holds even for a value the sensor wrote badly (without its
    sign, say); the empty reply, with or without its CRC, holds none. Whether a sensor's
    buffer still has data (R-4.4.5-10) is asked of the last reply read from it."""
    return any(c.isdigit() for c in reply.rstrip("\r\n")[1:])


def service_request(address: str) -> str:
    """The service request sensor ``address`` sends, CR LF included (R-4.4.6-01)."""
    return address + CRLF


def is_service_request(body: str, address: str) -> bool:
    """A service request is the bare address (R-4.4.6-01); anything else is not one."""
    return body == address


# -- aI! -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Identification(Checked):
    """The fields of an ``aI!`` reply; short replies leave the missing fields short or empty."""

    address: str
    version: str
    vendor: str
    model: str
    sensor_version: str
    optional: str
    violations: list[Violation] = field(default_factory=list)

    @property
    def version_number(self) -> int | None:
        """``ll`` as an integer (13, 14), or None when it is not two digits."""
        return int(self.version) if _digits(self.version, 2) else None


def parse_ident(body: str, expected_address: str | None = None) -> Identification:
    """Split an ``aI!`` body into its fixed-width fields (R-4.4.2-01) and check ``ll`` (-02)."""
    found = check_address(body, expected_address)
    if not IDENT_MIN <= len(body) <= IDENT_MAX:
        found.append(
            Violation(
                "R-4.4.2-01",
                f"identification '{escape(body)}' is {len(body)} characters long "
                f"(expected {IDENT_MIN} to {IDENT_MAX})",
            )
        )
    version = body[1:3]
    if not _digits(version, 2):
        found.append(
            Violation("R-4.4.2-02", f"version field '{escape(version)}' is not two digits")
        )
    return Identification(
        address=body[:1],
        version=version,
        vendor=body[3:11],
        model=body[11:17],
        sensor_version=body[17:20],
        optional=body[20:],
        violations=found,
    )


# -- atttn / atttnn / atttnnn --------------------------------------------------------------
@dataclass(frozen=True)
class MeasurementReply(Checked):
    """``atttn``-style reply; ``ttt``/``count`` are None when the field is not all digits."""

    address: str
    ttt: int | None
    count: int | None
    violations: list[Violation] = field(default_factory=list)


_FORMAT_REQ = {1: "R-4.4.5-01", 2: "R-4.4.7-01", 3: "R-5.1-01"}
_SHAPES = {1: "atttn", 2: "atttnn", 3: "atttnnn"}


def parse_measurement_reply(
    body: str,
    digits: int,
    *,
    expected_address: str | None = None,
    requirement: str | None = None,
) -> MeasurementReply:
    """Parse ``atttn`` (digits=1), ``atttnn`` (2) or ``atttnnn`` (3).

    The format requirement defaults to R-4.4.5-01 / R-4.4.7-01 / R-5.1-01 by ``digits``;
    pass ``requirement`` to name another (R-5.2-01 for HB). Count semantics (n = 0, nn > 20)
    depend on the command and are checked by :func:`check_measurement_count`.
    """
    if digits not in _FORMAT_REQ:
        raise ValueError(f"digits must be 1, 2 or 3, not {digits}")
    req = requirement or _FORMAT_REQ[digits]
    found = check_address(body, expected_address)
    ttt_text, count_text = body[1:4], body[4 : 4 + digits]
    if not _digits(body[1:], 3 + digits):
        found.append(
            Violation(req, f"reply '{escape(body)}' does not have the form {_SHAPES[digits]}")
        )
    ttt = int(ttt_text) if _digits(ttt_text, 3) else None
    count = int(count_text) if _digits(count_text, digits) else None
    return MeasurementReply(body[:1], ttt, count, found)


#: How many count digits a reply carries: the table lives in
#: :mod:`conformance.protocol.commands` (``count_digits``), re-exported under the name the
#: response parsers have always used.
measurement_digits = count_digits


def parse_measurement_reply_for(
    body: str, command: Command, *, expected_address: str | None = None
) -> MeasurementReply:
    """:func:`parse_measurement_reply` with digits and requirement taken from ``command``."""
    target = described(command)
    req = "R-5.2-01" if target.kind is Kind.HIGH_VOLUME_BINARY else None
    return parse_measurement_reply(
        body, measurement_digits(command), expected_address=expected_address, requirement=req
    )


def check_measurement_count(
    reply: MeasurementReply, command: Command, version: str | None = None
) -> list[Violation]:
    """Count rules that depend on the command (decisions A1 and A2).

    A zero count is legitimate only for an undefined numbered group or for HA/HB; plain
    M/MC/V must announce 1-9 (R-4.4.5-02) and plain C/CC must not answer ``a00000``
    (R-4.4.7-02). Under ``ll`` = 13 a concurrent count above 20 is a warning (R-4.4.7-03).
    The texts leave the command out: the judge leads each with it ("0C!: announced 25 values ...")
    """
    if reply.count is None:
        return []
    target = described(command)
    found = []
    if reply.count == 0 and target.group == 0:
        if target.kind in (Kind.MEASURE, Kind.VERIFY):
            found.append(Violation("R-4.4.5-02", "announced zero values; n must be 1 to 9"))
        elif target.kind is Kind.CONCURRENT:
            found.append(Violation("R-4.4.7-02", "announced zero values instead of measuring"))
    if target.kind is Kind.CONCURRENT and reply.count > 20 and version == V13:
        found.append(
            Violation(
                "R-4.4.7-03",
                f"announced {reply.count} values; the 2000 v1.3 text allows 20",
                warning=True,
            )
        )
    return found


# -- aDn! / aRn! ---------------------------------------------------------------------------
@dataclass(frozen=True)
class DataReply(Checked):
    """A D or R reply. ``crc`` is the CRC text found (None if none), ``crc_ok`` whether it
    matches the text before it (None when there is no CRC)."""

    address: str
    values: list[str]
    crc: str | None
    crc_ok: bool | None
    violations: list[Violation] = field(default_factory=list)

    @property
    def values_text(self) -> str:
        return "".join(self.values)


def expected_value_limit(command: Command) -> int:
    """Maximum ``<values>`` length for D replies after ``command`` or for an R reply (R-4.4-05).

    35 after M/MC/Mn/MCn/V (room for pre-1.2 recorders), 75 after the C family, HA and R.
    """
    kind = described(command).kind
    if kind in (Kind.MEASURE, Kind.VERIFY):
        return VALUES_MAX_MEASURE
    if kind in (Kind.CONCURRENT, Kind.HIGH_VOLUME_ASCII, Kind.CONTINUOUS):
        return VALUES_MAX
    raise ValueError(f"{command} is not followed by ASCII data replies")


def _crc_suffix_len(text: str) -> int:
    """Length of the run of CRC-range characters at the end (no value character is one)."""
    n = 0
    while n < len(text) and is_crc_char(text[-1 - n]):
        n += 1
    return n


def _check_crc(body: str, crc: str) -> tuple[bool, list[Violation]]:
    """Compare a three-character CRC with the one computed over the text before it."""
    found = []
    want = _ascii_crc(body[: -len(crc)])
    if not 0x40 <= ord(crc[0]) <= 0x4F:
        # not an encoding of any CRC-16: the encoding is wrong, its value cannot be compared
        found.append(
            Violation(
                "R-4.4.12-06",
                f"CRC '{escape(crc)}' cannot be an encoded CRC-16 (first character above 'O')",
            )
        )
    elif crc != want:
        found.append(
            Violation(
                "R-4.4.12-05",
                f"CRC '{escape(crc)}' does not match '{escape(want)}' computed over "
                f"'{escape(body[: -len(crc)])}'",
            )
        )
    return crc == want, found


def parse_data_reply(
    body: str,
    *,
    crc_expected: bool,
    limit: int,
    expected_address: str | None = None,
    limit_requirement: str = "R-4.4-05",
    crc_requirement: str = "R-4.4.12-02",
) -> DataReply:
    """Parse ``a<values>[<CRC>]`` and check it.

    A CRC is recognised by its character range (0x40-0x7F), which values never use. Checks:
    CRC presence (R-4.4.12-02, or ``crc_requirement``) or absence (R-4.4.12-03), CRC value
    (R-4.4.12-05) and encoding (R-4.4.12-06), the ``<values>`` length (R-4.4-05, or
    ``limit_requirement``) and every value's grammar (R-4.4.8-02 with decision A13).
    An empty value list is not an error here: it is the legal "aborted" reply, and whether
    values were due is the caller's knowledge (R-4.4.8-04).
    """
    found = check_address(body, expected_address)
    rest = body[1:]
    suffix = _crc_suffix_len(rest)
    crc: str | None = None
    crc_ok: bool | None = None
    if crc_expected:
        if suffix >= ASCII_CRC_LEN:
            crc = rest[-ASCII_CRC_LEN:]
            rest = rest[:-ASCII_CRC_LEN]
            crc_ok, crc_found = _check_crc(body, crc)
            found += crc_found
        else:
            found.append(
                Violation(crc_requirement, f"reply '{escape(body)}' lacks the 3-character CRC")
            )
            if suffix:
                crc = rest[-suffix:]
                rest = rest[:-suffix]
    elif suffix:
        crc = body[len(body) - suffix :]
        rest = rest[: len(rest) - suffix]
        if suffix == ASCII_CRC_LEN:
            crc_ok, _ = _check_crc(body, crc)
        found.append(
            Violation(
                "R-4.4.12-03",
                f"reply '{escape(body)}' ends with CRC-like characters '{escape(crc)}' "
                "although no CRC was requested",
            )
        )
    if len(rest) > limit:
        found.append(
            Violation(
                limit_requirement,
                f"<values> '{escape(rest)}' is {len(rest)} characters long (limit {limit})",
            )
        )
    values = split_values(rest)
    for value in values:
        found += check_value(value)
    return DataReply(body[:1], values, crc, crc_ok, found)


def parse_data_reply_for(
    body: str, command: Command, *, expected_address: str | None = None
) -> DataReply:
    """:func:`parse_data_reply` for a D reply after measurement ``command`` or an R reply.

    Picks the limit and CRC expectation and names the most specific requirements: R-5.1-03
    after HA, R-4.4.8.1-01 for R replies, R-4.4-05 / R-4.4.12-02 otherwise.
    """
    target = described(command)
    limit_req, crc_req = "R-4.4-05", "R-4.4.12-02"
    if target.kind is Kind.HIGH_VOLUME_ASCII:
        limit_req = crc_req = "R-5.1-03"
    elif target.kind is Kind.CONTINUOUS:
        limit_req = "R-4.4.8.1-01"
    elif target.kind not in MEASUREMENT_KINDS:
        raise ValueError(f"{command} is not followed by ASCII data replies")
    return parse_data_reply(
        body,
        crc_expected=target.returns_crc,
        limit=expected_value_limit(target),
        expected_address=expected_address,
        limit_requirement=limit_req,
        crc_requirement=crc_req,
    )


def check_data_sequence(replies: list[DataReply], announced: int, limit: int) -> list[Violation]:
    """Rules that span the D0, D1, ... replies of one measurement.

    R-4.4.8-03: the values add up to the announced count (a value split over two replies
    counted once). R-4.4.8.3-01: a later reply whose
    text starts without a sign continues a value cut off in the reply before. R-4.4.8.3-03
    (a warning): a reply left room for the next reply's first value.
    """
    found = []
    pairs = list(enumerate(zip(replies, replies[1:], strict=False), start=1))
    # a reply starting without a sign continues the value the reply before cut off: the
    # halves are one value (R-4.4.8.3-01 judges the cut), not one too many for the count.
    # Only a reply that held values can have cut one: after an empty D0 (a sensor whose
    # groups start at D1) an unsigned first value is R-4.4.8-02's missing sign, not the
    # rest of a split (groups-start-at-d1 + value-missing-sign, seed 4096)
    cut = {
        i for i, (before, after) in pairs if before.values and continues_split_value(after.values)
    }
    total = sum(len(r.values) for r in replies) - len(cut)
    if total != announced:
        found.append(
            Violation("R-4.4.8-03", f"{total} values were returned for {announced} announced")
        )
    for index, (before, after) in pairs:
        if not after.values:
            continue
        first = after.values[0]
        if index in cut:
            found.append(
                Violation(
                    "R-4.4.8.3-01",
                    f"D{index} starts with '{escape(first)}', the rest of a split value",
                )
            )
        elif before.values and len(before.values_text) + len(first) <= limit:
            found.append(
                Violation(
                    "R-4.4.8.3-03",
                    f"D{index - 1} had room for '{escape(first)}' returned by D{index}",
                    warning=True,
                )
            )
    return found


# -- aI..._nnn! ----------------------------------------------------------------------------
@dataclass(frozen=True)
class MetadataReply(Checked):
    """A metadata reply ``a,field1,field2[,...];[<CRC>]``; ``invalid_index`` marks the bare
    ``a[<CRC>]`` reply that says the value index does not exist (R-6.2-05)."""

    address: str
    fields: list[str]
    invalid_index: bool
    crc: str | None
    crc_ok: bool | None
    violations: list[Violation] = field(default_factory=list)


def parse_metadata_reply(
    body: str, *, crc_expected: bool, expected_address: str | None = None
) -> MetadataReply:
    """Parse and check a reply to ``aI<m>_nnn!``.

    Metadata fields are free text, so CRC characters cannot be told apart by range as in D
    replies; the CRC is taken by position when ``crc_expected``. Checks: overall format
    (R-6.2-02), field contents (R-6.2-03), length through ';' (R-6.2-04, decision A7), field 2
    present (R-6.2.2-01, and a warning when it is empty rather than a space), the
    invalid-index form (R-6.2-05) and the CRC (R-4.4.12-05/-06).
    """
    found = check_address(body, expected_address)
    address = body[:1]
    text = body
    crc: str | None = None
    crc_ok: bool | None = None
    if crc_expected:
        if crc_tail(body):
            crc = body[-ASCII_CRC_LEN:]
            text = body[:-ASCII_CRC_LEN]
            crc_ok, crc_found = _check_crc(body, crc)
            found += crc_found
        elif len(body) == 1:
            found.append(
                Violation("R-6.2-05", "invalid-index reply lacks the CRC the command asks for")
            )
            return MetadataReply(address, [], True, None, None, found)
        else:
            found.append(Violation("R-6.2-02", f"reply '{escape(body)}' lacks the CRC"))
    if len(text) == 1:
        return MetadataReply(address, [], True, crc, crc_ok, found)
    if not crc_expected and len(text) == 1 + ASCII_CRC_LEN and _ascii_crc(address) == text[1:]:
        found.append(
            Violation("R-6.2-05", f"invalid-index reply '{escape(body)}' carries an unasked CRC")
        )
        return MetadataReply(address, [], True, text[1:], True, found)
    tail = text[-ASCII_CRC_LEN:]
    if (
        not crc_expected
        and len(text) > 2 + ASCII_CRC_LEN
        and text[-ASCII_CRC_LEN - 1] == ";"
        and all(is_crc_char(c) for c in tail)
    ):  # one deviation, one violation: not also a ';' inside a field (R-6.2-03)
        found.append(
            Violation("R-6.2-02", f"reply '{escape(body)}' carries a CRC nobody asked for")
        )
        text = text[:-ASCII_CRC_LEN]
    fields = _metadata_fields(body, text, found)
    return MetadataReply(address, fields, False, crc, crc_ok, found)


def _metadata_fields(body: str, text: str, found: list[Violation]) -> list[str]:
    """The fields of ``text`` (the reply through ';', CRC taken off), appending to ``found``
    what is wrong with its frame and fields: kept apart from the CRC and invalid-index forms
    :func:`parse_metadata_reply` settles first, since only a field reply gets this far."""
    content = text[1:]
    if not content.startswith(","):
        found.append(Violation("R-6.2-02", f"reply '{escape(body)}' has no ',' after the address"))
    if not content.endswith(";"):
        found.append(Violation("R-6.2-02", f"reply '{escape(body)}' does not end with ';'"))
    inner = content[1 if content.startswith(",") else 0 :]
    inner = inner[:-1] if inner.endswith(";") else inner
    fields = inner.split(",")
    if ";" in inner:
        found.append(Violation("R-6.2-03", f"a field of '{escape(body)}' contains ';'"))
    if any(not 0x20 <= ord(c) <= 0x7E for c in inner):
        found.append(
            Violation("R-6.2-03", f"a field of '{escape(body)}' has non-printable characters")
        )
    if len(text) > METADATA_MAX_CHARS:
        found.append(
            Violation(
                "R-6.2-04",
                f"reply through ';' is {len(text)} characters long (limit {METADATA_MAX_CHARS})",
            )
        )
    if not fields[0]:
        found.append(Violation("R-6.2-02", f"reply '{escape(body)}' has an empty field 1"))
    if len(fields) < 2:
        found.append(Violation("R-6.2.2-01", f"reply '{escape(body)}' has no units field"))
    elif fields[1] == "":
        found.append(
            Violation(
                "R-6.2.2-01",
                f"units field of '{escape(body)}' is empty; a single space is recommended",
                warning=True,
            )
        )
    return fields
