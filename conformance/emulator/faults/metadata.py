"""Faults in identify-measurement and metadata replies (section 6)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from ...protocol.commands import Kind
from ..profile import MeasurementSpec
from ..replies import Reply, ReplyKind
from .edits import (
    only,
    silence,
    source_kind,
    toggle_crc,
    when,
    with_spec,
)
from .model import Fault, Rewrite


def _bump_count(body: str) -> str:
    last = int(body[-1])
    return body[:-1] + str(last + 1 if last < 9 else last - 1)


def _metadata_field(change: Callable[[list[str]], None]) -> Rewrite:
    """Rewrite the fields of metadata records (not the invalid-index replies)."""

    def rewrite(reply: Reply) -> Reply:
        if reply.kind is not ReplyKind.METADATA or "," not in reply.body:
            return reply
        head, _, rest = reply.body.partition(",")
        fields = rest.rstrip(";").split(",")
        change(fields)
        return replace(reply, body=head + "," + ",".join(fields) + ";")

    return rewrite


def _semicolon_in_units(fields: list[str]) -> None:
    if len(fields) > 1:  # a record another fault left without units (metadata-missing-units)
        fields[1] = fields[1] + ";x"  # keeps its one field: the other groups' show the ';'


def _long_identifier(fields: list[str]) -> None:
    fields[0] = "LONGIDENTIFIER"


def _last_record_dropped(spec: MeasurementSpec) -> MeasurementSpec:
    return replace(spec, metadata=spec.metadata[:-1])


def _long_record(spec: MeasurementSpec) -> MeasurementSpec:
    if not spec.metadata:
        return spec  # no record to lengthen (another fault removed the values)
    first = spec.metadata[0]
    return replace(spec, metadata=((*first, "x" * 70), *spec.metadata[1:]))


def _units_dropped(spec: MeasurementSpec) -> MeasurementSpec:
    return replace(spec, metadata=tuple(fields[:1] for fields in spec.metadata))


#: Metadata.
METADATA: tuple[Fault, ...] = (
    Fault(
        "metadata-missing-units",
        "Metadata records of aM! values carry only field 1 (no units field).",
        ("R-6.2.2-01",),
        profile=with_spec("M", _units_dropped),
        replaces="the fields of the metadata records of aM!",
    ),
    Fault(
        "metadata-too-long",
        "The metadata record of aM!'s first value is over 75 characters.",
        ("R-6.2-04",),
        profile=with_spec("M", _long_record),
        replaces="the fields of the metadata records of aM!",
    ),
    Fault(
        "metadata-no-invalid-index-reply",
        "Metadata commands for index 000 or past the count get no answer.",
        ("R-6.2-05", "R-6.2-06"),
        settings={"metadata_invalid_reply": False},
        needs=("v1.4",),
    ),
    Fault(
        "metadata-missing-record",
        "aIM_002! answers as if the index were invalid, though aM! has 3 values.",
        ("R-6.2-07",),
        rewrite=when(
            lambda r: (
                r.kind is ReplyKind.METADATA
                and r.command is not None
                and r.command.param == 2
                and source_kind(r) is Kind.MEASURE
                and r.source is not None
                and r.source.group == 0
            ),
            lambda r: replace(r, body=r.body[0]),
        ),
        needs=("v1.4",),
    ),
    Fault(
        "identify-reply-differs",
        "Identify-measurement replies announce a different count than the command does.",
        ("R-6.1-02",),
        rewrite=only([ReplyKind.IDENTIFY], lambda r: replace(r, body=_bump_count(r.body))),
        needs=("v1.4",),
    ),
    Fault(
        "identify-unsupported",
        "Identify-measurement commands (aIM!, aIC!, aIHA!...) get no answer."
        " With no identify reply there is none to compare with the measurement's (R-6.1-02),"
        " and nothing shows the sensor took one for an identify command (R-6.1-03).",
        ("R-6.1-01",),
        settings={"answer_identify_measurement": False},
        inconclusive=("R-6.1-02", "R-6.1-03"),
        needs=("v1.4",),
    ),
)


#: Added to complete the sensor-role coverage.
COVERAGE: tuple[Fault, ...] = (
    Fault(
        "metadata-silent",
        "Parameter metadata commands (aIM_001! ...) get no answer."
        " With no metadata reply, the rules on its contents have nothing to judge.",
        ("R-6.2-01", "R-6.2-05", "R-6.2-06", "R-6.2-07"),
        rewrite=only([ReplyKind.METADATA], silence),
        inconclusive=("R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2.1-01", "R-6.2.2-01"),
        masks=dict.fromkeys(
            (
                "metadata-crc-missing",
                "metadata-crc-unasked",
                "metadata-long-identifier",
                "metadata-semicolon-in-field",
            ),
            "metadata commands get no answer, so no metadata reply shows the deviation",
        ),
        needs=("v1.4",),
    ),
    Fault(
        "metadata-semicolon-in-field",
        "The units field of metadata records contains a ';'.",
        ("R-6.2-03",),
        rewrite=_metadata_field(_semicolon_in_units),
        needs=("v1.4",),
    ),
    Fault(
        "metadata-long-identifier",
        "Field 1 of metadata records is a 14-character name, not a SHEF code.",
        ("R-6.2.1-01",),
        rewrite=_metadata_field(_long_identifier),
        needs=("v1.4",),
    ),
)


#: Found on a third-party sensor (issue 10): the metadata count of R.
THIRD_PARTY_COUNT: tuple[Fault, ...] = (
    Fault(
        "metadata-r-count-short",
        "aIR0_nnn! describes one value fewer than aR0! returns.",
        ("R-6.2-06",),
        profile=with_spec("R0", _last_record_dropped),
    ),
)


#: Found on a third-party sensor (issue 10): an unasked metadata CRC.
THIRD_PARTY_CRC: tuple[Fault, ...] = (
    Fault(
        "metadata-crc-unasked",
        "Metadata replies of plain commands (aIM_001!) carry a CRC nobody asked for.",
        ("R-6.2-02",),
        rewrite=toggle_crc(ReplyKind.METADATA, crc=False),
        needs=("v1.4",),
    ),
)
