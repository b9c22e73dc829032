"""Faults in the form of replies: identification, reply framing, values and their length,
the ASCII and binary CRC, extended commands and multi-line text (4.2, 4.4.2, 4.4.8, 4.4.12,
4.4.13).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace

from ...protocol.commands import Kind
from ..profile import MeasurementSpec, Profile
from ..replies import Reply, ReplyKind
from .edits import (
    DATA_REPLIES,
    measure_family,
    only,
    packet_rewrite,
    set_to,
    source_kind,
    toggle_crc,
    when,
    with_spec,
)
from .model import Fault, Rewrite

_M_FAMILY = (Kind.MEASURE, Kind.VERIFY)
_C_FAMILY = (Kind.CONCURRENT,)


def _after(kinds: Iterable[Kind], *, crc: bool | None = None) -> Callable[[Reply], bool]:
    """Match D replies whose measurement was one of ``kinds`` (and a CRC variant or not)."""
    wanted = frozenset(kinds)

    def match(reply: Reply) -> bool:
        if reply.kind is not ReplyKind.DATA or source_kind(reply) not in wanted:
            return False
        return crc is None or (reply.source is not None and reply.source.crc == crc)

    return match


def _wrong_crc(reply: Reply) -> Reply:
    return replace(reply, crc_shift=reply.crc_shift + 1)


def _start_with(digits: int, change: Callable[[str], str]) -> Rewrite:
    def rewrite(reply: Reply) -> Reply:
        if measure_family(reply, digits):
            return replace(reply, body=change(reply.body))
        return reply

    return rewrite


def _binary_crc_wrong(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.crc_flip ^= 0x01


def _binary_crc_swapped(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.crc_swap = True


def _one_line_extended(reply: Reply) -> bool:
    """The serial-number command's reply, whatever letter the profile names it with (a fault
    renaming the extended commands, extended-not-x, must not undo this one)."""
    return (
        reply.kind is ReplyKind.EXTENDED
        and reply.command is not None
        and reply.command.body[1:] == "SN"
    )


def _crc_high_bits(reply: Reply) -> Reply:
    """The three CRC characters with 0x60 instead of 0x40 or'ed in (R-4.4.12-06)."""
    return replace(reply, crc_high=0x60) if reply.crc else reply


def _rename_extended(profile: Profile) -> Profile:
    """Extended commands without the recommended X (still not a basic command letter)."""
    return replace(profile, extended={"Z" + k[1:]: v for k, v in profile.extended.items()})


def _long_help_line(profile: Profile) -> Profile:
    """One 80-character line more in the multi-line help text, whatever its command is
    named (so a fault renaming the commands composes with this one in either order)."""
    extended = dict(profile.extended)
    name = next((k for k, text in extended.items() if "\n" in text), "XHELP")
    extended[name] = extended[name] + "\n" + "L" * 80  # KeyError: a sensor without one
    return replace(profile, extended=extended)


def _first_value(new: str) -> Callable[[MeasurementSpec], MeasurementSpec]:
    """Replace the first value; a measurement without values keeps none (it has no first
    value to spoil, and inventing one would undo the fault that removed them)."""
    return lambda spec: replace(spec, values=(new, *spec.values[1:])) if spec.values else spec


def _long_continuous(spec: MeasurementSpec) -> MeasurementSpec:
    """R0 with 82 value characters; metadata grows along so only the length deviates. The
    extra values go first, so a fault that drops R0's last record composes in either order."""
    extra = ("+1234.567",) * 8
    metadata = (*(("XL", " ") for _ in extra), *spec.metadata)
    return replace(spec, values=extra + spec.values, metadata=metadata)


def _crc_twin(profile: Profile) -> Profile:
    plain = profile.measurements["M"]
    twin = replace(plain, values=plain.values[:-1], metadata=plain.metadata[:-1])
    return replace(profile, measurements={**profile.measurements, "MC": twin})


#: The D-reply and value rules (testcases/sensor/test_4_4_8_data.py's first three cases):
#: INCONCLUSIVE where a start reply gives no readable count, since no D command follows it
#: and the values it holds are never read (judges.measurements.unread_data).
UNREAD_DATA = (
    "R-4.4.8-01",
    "R-4.4.8-02",
    "R-4.4-05",
    "R-4.4.8-03",
    "R-4.4.8-04",
    "R-4.4.8.3-01",
    "R-4.4.8.3-02",
    "R-4.4.8.3-03",
)

#: The metadata record rules (testcases/sensor/test_6_metadata.py's records): INCONCLUSIVE
#: where neither a measurement's start reply nor its identify reply gives a readable count,
#: since none of that group's records is asked for (judges.metadata.uncounted_groups).
UNREAD_RECORDS = ("R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2-07", "R-6.2.1-01", "R-6.2.2-01")


#: Identification and reply format.
FORMAT: tuple[Fault, ...] = (
    Fault(
        "ident-optional-too-long",
        "aI! carries a 14-character optional field, making the reply 34 characters.",
        ("R-4.4.2-01",),
        rewrite=only([ReplyKind.IDENTIFICATION], lambda r: replace(r, body=r.body + "EXTRA.ME")),
        replaces="the length of the aI! reply",
    ),
    Fault(
        "ident-truncated",
        "aI! stops after the model field: sensor version and optional field are missing.",
        ("R-4.4.2-01",),
        rewrite=only([ReplyKind.IDENTIFICATION], lambda r: replace(r, body=r.body[:17])),
        replaces="the length of the aI! reply",
    ),
    Fault(
        "ident-bad-version",
        "aI! gives the SDI-12 version as 'V4' instead of two digits."
        " The tool retries that reply, its later tries after breaks of its own, so the aI!"
        " sent into a running concurrent measurement cannot be told from those breaks as what"
        " aborted it (R-4.4.7.1-01/02).",
        ("R-4.4.2-02",),
        rewrite=only(
            [ReplyKind.IDENTIFICATION], lambda r: replace(r, body=r.body[0] + "V4" + r.body[3:])
        ),
        inconclusive=("R-4.4.7.1-01", "R-4.4.7.1-02"),
    ),
    Fault(
        "ack-trailing-space",
        "a! answers 'a <CR><LF>' with a space after the address.",
        ("R-4.4.1-01",),
        rewrite=only([ReplyKind.ACKNOWLEDGE], lambda r: replace(r, body=r.body + " ")),
    ),
    Fault(
        "measure-ttt-two-digits",
        "M/MC/Mn/V replies give ttt with two digits (atttn becomes attn)."
        " No measurement reply parses, so no data are there for the identify commands to"
        " disturb (R-6.1-03), no ttt tells whether aV! owes a service request as aM! does"
        " (R-4.4.11-01), and no count (aIM! answers alike) says which metadata records"
        " the M-type groups owe (R-6.2-07), so none of theirs is read (the record rules)."
        " With no count no D command follows aM!, aV!"
        " or any aMn!: the D-reply and value rules (R-4.4.8-*, R-4.4-05, R-4.4.8.3-*) read"
        " only aC!'s data and are left open for the values aM! holds, as is the count's"
        " 1..9 rule (R-4.4.5-02). Nor can aM!'s count be set beside aMC!'s"
        " (R-4.4.12-04).",
        ("R-4.4.5-01",),
        rewrite=_start_with(1, lambda body: body[0] + body[2:]),
        inconclusive=(
            "R-6.1-03",
            "R-4.4.11-01",
            *UNREAD_RECORDS,
            "R-4.4.5-02",
            "R-4.4.12-04",
            *UNREAD_DATA,
        ),
    ),
    Fault(
        "measure-count-zero",
        "aM!/aMC! announce n = 0 for the defined measurement and deliver no values.",
        ("R-4.4.5-02",),
        profile=with_spec("M", lambda s: replace(s, values=(), metadata=())),
        replaces="the count aM! announces against the values it delivers",
        masks={
            **dict.fromkeys(
                ("value-missing-sign", "value-eight-digits", "value-ten-chars", "value-two-points"),
                "aM! without values has no first value to spoil",
            ),
            "metadata-missing-units": "aM! without values has no metadata record",
            "metadata-too-long": "aM! without values has no metadata record",
        },
    ),
    Fault(
        "concurrent-three-digit-count",
        "C/CC/Cn replies give a 3-digit count (atttnnn instead of atttnn)."
        " No concurrent reply has a readable count, so its bound (R-4.4.7-03) has nothing"
        " to judge, and no D command follows aC!, aCC!, aC9!, aCC9!: the D-reply and value"
        " rules (R-4.4.8-*, R-4.4-05, R-4.4.8.3-*) read only the M family's data and are"
        " left open for the values those hold. Nor can aC!'s count be set beside aCC!'s"
        " (R-4.4.12-04).",
        ("R-4.4.7-01",),
        inconclusive=(
            "R-4.4.7-03",
            "R-4.4.12-04",
            *UNREAD_DATA,
        ),
        rewrite=_start_with(2, lambda body: body[:4] + "0" + body[4:]),
    ),
    Fault(
        "concurrent-zero",
        "aC!/aCC! answer a00000 (no values) for the plain concurrent measurement: no"
        " measurement, so aC! is not supported either.",
        ("R-4.4.7-02", "R-4.4.7-08"),
        profile=with_spec("C", lambda s: replace(s, values=(), metadata=(), ttt=0)),
        replaces="the values of aC!",
    ),
    Fault(
        "high-volume-two-digit-count",
        "HA replies give a 2-digit count (atttnn instead of atttnnn)."
        " With the count unreadable no D data are asked for, so the aHA! data rules have"
        " nothing to judge, nor has the count aHA!'s metadata records are checked against"
        " (aIHA! answers alike, R-6.2-07) nor its records read; the announced-count rules"
        " of the D data (R-4.4.8-03/-04) are left open for aHA!'s.",
        ("R-5.1-01",),
        rewrite=when(
            lambda r: measure_family(r, 3) and source_kind(r) is Kind.HIGH_VOLUME_ASCII,
            lambda r: replace(r, body=r.body[:4] + r.body[5:]),
        ),
        inconclusive=("R-5.1-02", "R-5.1-03", *UNREAD_RECORDS, "R-4.4.8-03", "R-4.4.8-04"),
        needs=("HA",),
    ),
    Fault(
        "value-missing-sign",
        "The first value of aM! has no sign ('22.15' instead of '+22.15').",
        ("R-4.4.8-02",),
        profile=with_spec("M", _first_value("22.15")),
        replaces="the first value of aM!",
    ),
    Fault(
        "value-eight-digits",
        "The first value of aM! has eight digits ('+12345678').",
        ("R-4.4.8-02",),
        profile=with_spec("M", _first_value("+12345678")),
        replaces="the first value of aM!",
    ),
    Fault(
        "value-ten-chars",
        "The first value of aM! is ten characters long ('+12345.678').",
        ("R-4.4.8-02",),
        profile=with_spec("M", _first_value("+12345.678")),
        replaces="the first value of aM!",
    ),
    Fault(
        "value-two-points",
        "The first value of aM! has two decimal points ('+22.1.5').",
        ("R-4.4.8-02",),
        profile=with_spec("M", _first_value("+22.1.5")),
        replaces="the first value of aM!",
    ),
    Fault(
        "values-over-35",
        "D replies after M/MC/Mn/V pack up to 40 value characters (M2 shows it).",
        ("R-4.4-05",),
        settings={"limit_measure": 40},
    ),
    Fault(
        "values-over-75",
        "D replies after C/CC/Cn pack up to 80 value characters.",
        ("R-4.4-05",),
        settings={"limit_concurrent": 80},
    ),
    Fault(
        "high-volume-values-over-75",
        "D replies after HA pack up to 81 value characters.",
        ("R-5.1-03",),
        settings={"limit_high_volume": 81},
        needs=("HA",),
    ),
    Fault(
        "continuous-over-75",
        "aR0!/aRC0! return 82 value characters.",
        ("R-4.4.8.1-01",),
        profile=with_spec("R0", _long_continuous),
    ),
    Fault(
        "split-value",
        "D replies after M/V are filled to exactly 35 characters, cutting a value in two.",
        ("R-4.4.8.3-01",),
        settings={"split_values": True},
    ),
    Fault(
        "values-not-packed",
        "D replies after M/V hold one value fewer than would fit (e.g. M2 needs D0..D4).",
        ("R-4.4.8.3-03",),
        settings={"pack_slack": 1},
    ),
    Fault(
        "missing-crlf",
        "D replies end without CR LF.",
        ("R-4.2-03",),
        rewrite=only(DATA_REPLIES, set_to(end="")),
    ),
    Fault(
        "non-printable-char",
        "The extended command's reply contains a BEL (0x07) character.",
        ("R-4.2-02",),
        rewrite=only([ReplyKind.EXTENDED], lambda r: replace(r, body=r.body + "\x07")),
    ),
    Fault(
        "wrong-reply-address",
        "D replies start with the next address instead of the sensor's own.",
        ("R-4.3-01",),
        rewrite=only(
            DATA_REPLIES, lambda r: replace(r, body=("1" if r.body[0] != "1" else "2") + r.body[1:])
        ),
    ),
    Fault(
        "parity-error",
        "The LF of every a! reply is sent with odd parity.",
        ("R-4.1-02",),
        rewrite=only([ReplyKind.ACKNOWLEDGE], set_to(flip_parity=(-1,))),
    ),
    Fault(
        "extended-no-crlf",
        "The one-line extended command's reply (aXSN!) ends without CR LF.",
        ("R-4.4.13-01", "R-4.2-03"),
        rewrite=when(_one_line_extended, set_to(end="")),
    ),
)


#: CRC.
CRC: tuple[Fault, ...] = (
    Fault(
        "wrong-crc",
        "Every ASCII CRC is off by one in its last character.",
        ("R-4.4.12-05",),
        rewrite=lambda r: _wrong_crc(r) if r.crc and r.binary is None else r,
    ),
    Fault(
        "crc-missing",
        "D replies after MC/MCn/CC/CCn carry no CRC.",
        ("R-4.4.12-02",),
        rewrite=when(_after([Kind.MEASURE, Kind.CONCURRENT], crc=True), set_to(crc=False)),
    ),
    Fault(
        "high-volume-crc-missing",
        "D replies after HA carry no CRC.",
        ("R-5.1-03",),
        rewrite=when(_after([Kind.HIGH_VOLUME_ASCII]), set_to(crc=False)),
        needs=("HA",),
    ),
    Fault(
        "crc-on-plain",
        "D replies after plain M/Mn/V/C/Cn carry a CRC.",
        ("R-4.4.12-03",),
        rewrite=when(_after([*_M_FAMILY, *_C_FAMILY], crc=False), set_to(crc=True)),
    ),
    Fault(
        "crc-on-continuous",
        "aRn! replies (no CRC requested) carry a CRC.",
        ("R-4.4.12-03",),
        rewrite=toggle_crc(ReplyKind.CONTINUOUS, crc=False),
    ),
    Fault(
        "continuous-crc-missing",
        "aRCn! replies for supported Rn carry no CRC.",
        ("R-4.4.12-02",),
        rewrite=toggle_crc(ReplyKind.CONTINUOUS, crc=True),
    ),
    Fault(
        "unsupported-rc-without-crc",
        "aRCn! for an unsupported n answers 'a<CR><LF>' instead of 'a<CRC><CR><LF>'.",
        ("R-4.4.8.1-03", "R-4.4.12-02"),
        rewrite=toggle_crc(ReplyKind.CONTINUOUS, crc=True, values=False),
    ),
    Fault(
        "metadata-crc-missing",
        "Metadata replies for CRC commands (aIMC_nnn!, aICC_nnn!, aIHA_nnn!...) lack the CRC.",
        ("R-6.2-02",),
        rewrite=toggle_crc(ReplyKind.METADATA, crc=True),
        needs=("v1.4",),
    ),
    Fault(
        "crc-variant-different-count",
        "aMC! measures one value fewer than aM! (n 2 instead of 3).",
        ("R-4.4.12-04",),
        profile=_crc_twin,
    ),
    Fault(
        "binary-crc-wrong",
        "High-volume binary packets carry a wrong CRC.",
        ("R-5.2-03",),
        rewrite=packet_rewrite(_binary_crc_wrong),
        needs=("HB",),
    ),
    Fault(
        "binary-crc-big-endian",
        "High-volume binary packets send the CRC high byte first.",
        ("R-5.2-03",),
        rewrite=packet_rewrite(_binary_crc_swapped),
        needs=("HB",),
    ),
)


#: Added to complete the sensor-role coverage.
COVERAGE: tuple[Fault, ...] = (
    Fault(
        "crc-wrong-encoding",
        "CRC characters are or'ed with 0x60 instead of 0x40; a CRC so encoded is not compared"
        " with its text, so its value (R-4.4.12-05) is undecided (seed 4118).",
        ("R-4.4.12-06",),
        rewrite=_crc_high_bits,
        inconclusive=("R-4.4.12-05",),
    ),
    Fault(
        "extended-not-x",
        "Extended commands are named aZ...! instead of the recommended aX...!.",
        ("R-4.4.13-02",),
        profile=_rename_extended,
        declares=_rename_extended,  # its maker lists aZSN!...; the sensor must answer them
    ),
    Fault(
        "multiline-no-etx",
        "Multi-line text ends without the ETX after the last CR LF.",
        ("R-4.4.13.1-01",),
        settings={"etx": False},
        needs=("XHELP",),
    ),
    Fault(
        "multiline-long-line",
        "A line of the multi-line help text has 80 characters (75 allowed).",
        ("R-4.4.13.1-02",),
        profile=_long_help_line,
    ),
    Fault(
        "multiline-slow-lines",
        "Lines of multi-line text come 200 ms apart (150 ms allowed).",
        ("R-4.4.13.1-03",),
        settings={"line_gap": 0.2},
        needs=("XHELP",),
    ),
)


#: Found on a third-party sensor (issue 10): a CRC request that outlives its command.
THIRD_PARTY: tuple[Fault, ...] = (
    Fault(
        "metadata-crc-sticks",
        "After a CRC metadata command (aIMC_001!), D replies of later plain measurements "
        "carry a CRC too.",
        ("R-4.4.12-03",),
        settings={"metadata_crc_sticks": True},
        needs=("v1.4",),
    ),
)
