"""The conforming examples of the SDI-12 v1.4 (2023) text must parse and validate clean.

Each example is transcribed in the document's own notation (``<CR><LF>``, command and reply
on one line, a service request on a line of its own) and replayed through the command grammar
and the response parsers, with the measurement context a recorder would have. The known typos
of requirements.md section 4 are kept as separate cases that must be flagged, so the suite can
never silently copy them.

Not covered here: the ``aI!`` example (lost from every source text), the 4.4.8.4 d / 4.4.12.3 d
missing service request (a timing matter judged on transcripts) and the multi-line text example
(decision A10, parsed elsewhere).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from conformance.protocol import commands as c
from conformance.protocol.binary import DataType, parse_binary_packet
from conformance.protocol.commands import Command, Kind, parse_command
from conformance.protocol.responses import (
    DataReply,
    Violation,
    check_address_reply,
    check_change_address_reply,
    check_data_sequence,
    check_measurement_count,
    expected_value_limit,
    is_service_request,
    parse_data_reply_for,
    parse_ident,
    parse_measurement_reply_for,
    parse_metadata_reply,
    split_line,
)


def wire(notation: str) -> str:
    """Document notation to wire text: ``<CR><LF>`` -> CR LF (nothing else is rewritten)."""
    return notation.replace("<CR><LF>", "\r\n")


@dataclass
class Replay:
    """What a recorder learns while replaying an example: violations, announced counts and
    the values collected per measurement."""

    violations: list[Violation] = field(default_factory=list)
    pending: dict[str, Command] = field(default_factory=dict)
    announced: dict[str, int] = field(default_factory=dict)
    collected: dict[str, list] = field(default_factory=dict)
    replies: dict[str, list[DataReply]] = field(default_factory=dict)
    service_requests: int = 0

    def line(self, notation: str) -> None:
        """One line of an example: ``<command>!<reply>`` or a bare service request."""
        text = wire(notation)
        if "!" not in text:  # a service request on its own line
            body, found = split_line(text)
            self.violations += found
            assert any(is_service_request(body, a) for a in self.pending), notation
            self.service_requests += 1
            return
        cut = text.index("!") + 1
        self.exchange(parse_command(text[:cut]), text[cut:])

    def exchange(self, command: Command, raw: str) -> None:
        crc = 3 if _reply_has_crc(command, self.pending.get(command.address)) else 0
        body, found = split_line(raw, crc_positions=crc)
        self.violations += found
        a = command.address
        match command.kind:
            case Kind.ACKNOWLEDGE:
                self.violations += check_address_reply(body, a, "R-4.4.1-01")
            case Kind.QUERY_ADDRESS:
                self.violations += check_address_reply(body, None, "R-4.4.3-01")
            case Kind.CHANGE_ADDRESS:
                self.violations += check_change_address_reply(body, a, command.new_address)
            case Kind.IDENTIFY:
                self.violations += parse_ident(body, expected_address=a).violations
            case Kind.IDENTIFY_MEASUREMENT:
                reply = parse_measurement_reply_for(body, command, expected_address=a)
                self.violations += reply.violations + check_measurement_count(reply, command)
            case Kind.METADATA:
                assert command.target is not None
                meta = parse_metadata_reply(
                    body, crc_expected=command.target.returns_crc, expected_address=a
                )
                self.violations += meta.violations
            case Kind.DATA:
                reply = parse_data_reply_for(body, self.pending[a], expected_address=a)
                self.violations += reply.violations
                self.collected[a] += reply.values
                self.replies[a].append(reply)
            case Kind.CONTINUOUS:
                reply = parse_data_reply_for(body, command, expected_address=a)
                self.violations += reply.violations
            case _ if command.starts_measurement:
                reply = parse_measurement_reply_for(body, command, expected_address=a)
                self.violations += reply.violations + check_measurement_count(reply, command)
                self.pending[a] = command
                self.announced[a] = reply.count or 0
                self.collected[a] = []
                self.replies[a] = []
            case _:
                raise AssertionError(f"no replay rule for {command}")

    def sequence_violations(self) -> list[Violation]:
        """Rules across D0, D1, ...: count (R-4.4.8-03), split values, packing (R-4.4.8.3-*)."""
        found = []
        for a, n in self.announced.items():
            if self.replies[a]:
                limit = expected_value_limit(self.pending[a])
                found += check_data_sequence(self.replies[a], n, limit)
        return found


def _reply_has_crc(command: Command, pending: Command | None) -> bool:
    if command.kind is Kind.DATA:
        return pending is not None and pending.returns_crc
    if command.kind is Kind.METADATA and command.target is not None:
        return command.target.returns_crc
    return command.kind is Kind.CONTINUOUS and command.crc


EXAMPLES: dict[str, list[str]] = {
    "4.4.1.1 a!": ["0!0<CR><LF>", "1!1<CR><LF>"],
    "4.4.3 ?! (prose)": ["?!0<CR><LF>"],
    "4.4.4 aAb! (Table 8)": ["0A3!3<CR><LF>", "3A0!0<CR><LF>"],
    "4.4.4 aAb! refused (Table 8)": ["0A3!0<CR><LF>"],
    "4.4.5 M": ["0M!00101<CR><LF>", "0<CR><LF>", "0D0!0+3.14<CR><LF>"],
    "4.4.8.1 RC unsupported": ["0RC0!0AP@<CR><LF>"],
    "4.4.8.2 R0": ["0R0!0+3.14<CR><LF>"],
    "4.4.8.4 a": ["0M!00001<CR><LF>", "0D0!0+3.14<CR><LF>"],
    "4.4.8.4 b": ["0M!00053<CR><LF>", "0<CR><LF>", "0D0!0+3.14+2.718+1.414<CR><LF>"],
    "4.4.8.4 c": [
        "0M!00359<CR><LF>",
        "0<CR><LF>",
        "0D0!0+1.11+2.22+3.33+4.44+5.55+6.66<CR><LF>",
        "0D1!0+7.77+8.88+9.99<CR><LF>",
    ],
    "4.4.8.4 d": ["0M!00012<CR><LF>", "0D0!0+3.14+2.718<CR><LF>"],
    "4.4.8.4 e": [
        "0M!00053<CR><LF>",
        "0<CR><LF>",
        "0D0!0+3.14<CR><LF>",
        "0D1!0+2.718<CR><LF>",
        "0D2!0+1.414<CR><LF>",
    ],
    "4.4.8.5 C": [
        "0C!004512<CR><LF>",
        "1C!101504<CR><LF>",
        "1D0!1+1.23+2.34+345+4.4678<CR><LF>",
        "0D0!0+1.234-4.56+12354-0.00045+2.223+145.5+7.7003+4328.8+9+10+11.433+12<CR><LF>",
    ],
    "4.4.9.1 a": ["0M1!00011<CR><LF>", "0<CR><LF>", "0D0!0+3.14<CR><LF>"],
    "4.4.9.1 b": [
        "0M2!00359<CR><LF>",
        "0<CR><LF>",
        "0D0!0+1.11+2.22+3.33+4.44+5.55+6.66<CR><LF>",
        "0D1!0+7.77+8.88+9.99<CR><LF>",
    ],
    "4.4.11.1 V": ["0V!00011<CR><LF>", "0<CR><LF>", "0D0!0+1<CR><LF>"],
    "4.4.12.3 a": ["0MC!00001<CR><LF>", "0D0!0+3.14OqZ<CR><LF>"],
    "4.4.12.3 b": ["0MC!00053<CR><LF>", "0<CR><LF>", "0D0!0+3.14+2.718+1.414Ipz<CR><LF>"],
    "4.4.12.3 c": [
        "0MC!00359<CR><LF>",
        "0<CR><LF>",
        "0D0!0+1.11+2.22+3.33+4.44+5.55+6.66I]q<CR><LF>",
        "0D1!0+7.77+8.88+9.99IvW<CR><LF>",
    ],
    "4.4.12.3 d": ["0MC!00012<CR><LF>", "0D0!0+3.14+2.718IWO<CR><LF>"],
    "4.4.12.3 e": [
        "0MC!00053<CR><LF>",
        "0<CR><LF>",
        "0D0!0+3.14OqZ<CR><LF>",
        "0D1!0+2.718Gbc<CR><LF>",
        "0D2!0+1.414GtW<CR><LF>",
    ],
    # f: the text wraps the last reply before "Ba]"; the wrap is layout, not wire content.
    "4.4.12.3 f": [
        "0CC!004512<CR><LF>",
        "1CC!101504<CR><LF>",
        "1D0!1+1.23+2.34+345+4.4678KoO<CR><LF>",
        "0D0!0+1.234-4.56+12354-0.00045+2.223+145.5+7.7003+4328.8+9+10+11.433+12Ba]<CR><LF>",
    ],
    # 5.1.1 prints "1CC!101504<CR><LF" (missing '>'); see test_missing_angle_bracket_typo.
    "5.1.1 HA": [
        "0HA!0045012<CR><LF>",
        "1CC!101504<CR><LF>",
        "1D0!1+1.23+2.34+345+4.4678KoO<CR><LF>",
        "0D0!0+1.234-4.56+12354-0.00045+2.223+145.5+7.7003+4328.8+9+10+11.433+12Ba]<CR><LF>",
    ],
    "6.1.1 a": ["8IM!80001<CR><LF>"],
    "6.1.1 b": ["8IM!80109<CR><LF>"],
    "6.1.1 c": ["8IC5!801099<CR><LF>"],
    "6.2.4 a (metadata line)": ["0IM_001!0,field1,field2,field3;<CR><LF>"],
    "6.2.4 b": ["0IM!00001<CR><LF>", "0IM_001!0,PR,mm,precipitation rate per day;<CR><LF>"],
    "6.2.4 c": [
        "0ICC!000502<CR><LF>",
        "0ICC_001!0,CU,degrees C,average air temperature,calibration data,40,1235;@|e<CR><LF>",
    ],
}


#: Examples whose sensor leaves room in a D reply: legal, but R-4.4.8.3-03 (SHOULD) warns.
#: 4.4.8.4 c / 4.4.12.3 c put six values in D0 although a seventh fits in exactly 35.
PACKING_WARNINGS = {
    "4.4.8.4 c": 1,
    "4.4.8.4 e": 2,
    "4.4.9.1 b": 1,
    "4.4.12.3 c": 1,
    "4.4.12.3 e": 2,
}


@pytest.mark.parametrize("name", EXAMPLES)
def test_spec_example_is_clean(name: str) -> None:
    replay = Replay()
    for line in EXAMPLES[name]:
        replay.line(line)
    assert replay.violations == []
    sequence = replay.sequence_violations()
    assert [v.requirement for v in sequence] == ["R-4.4.8.3-03"] * PACKING_WARNINGS.get(name, 0)
    assert all(v.warning for v in sequence)


def test_example_c_needs_d1_under_35_characters() -> None:
    """4.4.8.4 c: the nine values do not fit the 35-character limit of one D reply."""
    nine = "0+1.11+2.22+3.33+4.44+5.55+6.66+7.77+8.88+9.99"
    reply = parse_data_reply_for(nine, c.measure("0"))
    assert [v.requirement for v in reply.violations] == ["R-4.4-05"]
    assert parse_data_reply_for(nine, c.concurrent("0")).violations == []


def test_service_requests_are_counted() -> None:
    replay = Replay()
    for line in EXAMPLES["4.4.8.4 c"]:
        replay.line(line)
    assert replay.service_requests == 1


def test_example_6_2_4_a_identify_reply_is_malformed() -> None:
    """The text prints ``0IM!0001!<CR><LF>``: a four-character atttn with a stray '!'."""
    replay = Replay()
    replay.line("0IM!0001!<CR><LF>")
    assert [v.requirement for v in replay.violations] == ["R-4.4.5-01"]


def test_missing_angle_bracket_typo() -> None:
    """5.1.1 prints ``1CC!101504<CR><LF``: read literally there is no CR LF on the wire."""
    replay = Replay()
    replay.line("1CC!101504<CR><LF")
    assert "R-4.2-03" in [v.requirement for v in replay.violations]


def test_crc_example_with_the_2000_typo_is_flagged() -> None:
    """v1.3 (2000) 4.4.12.3 f carries ``+1.1234`` with CRC ``Ba]``: that CRC is wrong."""
    replay = Replay()
    replay.line("0CC!004512<CR><LF>")
    replay.line(
        "0D0!0+1.1234-4.56+12354-0.00045+2.223+145.5+7.7003+4328.8+9+10+11.433+12Ba]<CR><LF>"
    )
    assert [v.requirement for v in replay.violations] == ["R-4.4.12-05"]


TABLE_18 = [
    ("1DB0!", "31 04 00 03 FF FF 01 00 C2 AC", DataType.INT16, [-1, 1]),
    ("1DB1!", "31 08 00 09 C3 F5 48 40 00 00 80 3F 3B 6E", DataType.FLOAT32, [3.14, 1.0]),
    ("1DB2!", "31 00 00 00 0E FC", DataType.INVALID, []),
]


def test_hb_example_5_2_2() -> None:
    """1HB! announces four values; DB0 and DB1 deliver them, DB2 is the empty packet."""
    replay = Replay()
    replay.line("1HB!1005004<CR><LF>")
    assert replay.violations == [] and replay.announced == {"1": 4}
    received: list[float] = []
    for command_text, packet_hex, dtype, values in TABLE_18:
        command = parse_command(command_text)
        assert command == c.binary_data("1", command.index)
        packet = parse_binary_packet(bytes.fromhex(packet_hex), expected_address="1")
        assert packet.violations == [] and packet.crc_ok
        assert packet.dtype is dtype
        assert packet.values == pytest.approx(values, rel=1e-7)
        received += packet.values
    assert packet.is_empty
    assert len(received) == replay.announced["1"]  # R-5.2-07
