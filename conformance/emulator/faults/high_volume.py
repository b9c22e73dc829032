"""Faults in high-volume ASCII and binary measurements and their packets (section 5)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from ...protocol.binary import DataType, type_size
from ...protocol.commands import HIGH_VOLUME_KINDS, Kind
from ..profile import MeasurementSpec, Packet, Profile
from ..replies import Reply, ReplyKind
from .edits import (
    measure_family,
    packet_rewrite,
    silence,
    source_kind,
    when,
    with_spec,
)
from .model import Fault
from .replies import UNREAD_RECORDS


def _binary_first_packet(change: Callable[[Reply], None]) -> Callable[[Reply], None]:
    """Apply ``change`` to the DB0 packet only (when it carries data)."""

    def apply(reply: Reply) -> None:
        first = reply.command is not None and reply.command.index == 0
        if first and reply.binary is not None and reply.binary.payload:
            change(reply)

    return apply


def _pad_payload(reply: Reply) -> None:
    """One stray byte after the values of a multi-byte type (an int8 payload cannot show it).
    A type code no table lists (binary-invalid-type's 11 on DB0, whose values are int8) has
    no size to pad against and is left as it is, so the two compose in either order (seed
    4183: type_size(11) raised inside the sensor, 21 requirements ERROR)."""
    assert reply.binary is not None
    known = reply.binary.dtype in _TYPE_CODES
    if reply.binary.payload and known and type_size(reply.binary.dtype) > 1:
        reply.binary.payload += b"\x00"


_TYPE_CODES = frozenset(int(t) for t in DataType)


def _invalid_type(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.dtype = 11


def _parity_address(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.address |= 0x80


def _hb_start(reply: Reply) -> bool:
    return measure_family(reply, 3) and source_kind(reply) is Kind.HIGH_VOLUME_BINARY


def _hv_start(reply: Reply) -> bool:
    return reply.kind is ReplyKind.START and source_kind(reply) in HIGH_VOLUME_KINDS


def _size_big_endian(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.size_order = "big"


def _without_high_volume(profile: Profile) -> Profile:
    keep = {k: v for k, v in profile.measurements.items() if k not in ("HA", "HB")}
    return replace(profile, measurements=keep)


def _extra_meta(spec: MeasurementSpec) -> tuple[tuple[str, ...], ...]:
    return (*spec.metadata, ("XX", " ", "extra"))


def _big_packet(spec: MeasurementSpec) -> MeasurementSpec:
    packet = Packet(DataType.UINT16, tuple(range(501)))  # 1002 payload bytes
    metadata = (*spec.metadata, *(("XB", " ") for _ in range(501)))
    return replace(spec, packets=(*spec.packets, packet), metadata=metadata)


#: High-volume binary.
BINARY: tuple[Fault, ...] = (
    Fault(
        "binary-payload-not-multiple",
        "Packets of multi-byte types carry one stray byte after their values."
        " No packet reads as values, so none shows how the values are ordered (R-5.2-07).",
        ("R-5.2-05",),
        rewrite=packet_rewrite(_pad_payload),
        inconclusive=("R-5.2-07",),
        needs=("HB",),
    ),
    Fault(
        "binary-invalid-type",
        "DB0's packet carries data type code 11."
        " No packet reads as values, so none shows how the values are ordered (R-5.2-07).",
        ("R-5.2.1-01",),
        rewrite=packet_rewrite(_binary_first_packet(_invalid_type)),
        inconclusive=("R-5.2-07",),
        needs=("HB",),
    ),
    Fault(
        "binary-no-empty-packet",
        "aDBn! past the data gets no answer instead of the 6-byte empty packet.",
        ("R-5.2-06",),
        settings={"empty_packet": False},
        needs=("HB",),
    ),
    Fault(
        "binary-payload-over-1000",
        "HB adds an eleventh packet of 501 uint16 values: 1002 payload bytes.",
        ("R-5.2-04",),
        profile=with_spec("HB", _big_packet),
        replaces="the count aHB! announces against the values its packets deliver",
    ),
    Fault(
        "binary-address-parity",
        "The address byte of DB packets carries a parity bit in bit 7 (not 8N1).",
        ("R-4.1-03",),
        rewrite=packet_rewrite(_parity_address),
        needs=("HB",),
    ),
    Fault(
        "binary-fewer-values",
        "aHB! announces one value more than the DB packets deliver.",
        ("R-5.2-07",),
        profile=with_spec(
            "HB", lambda s: replace(s, announced=s.count + 1, metadata=_extra_meta(s))
        ),
        replaces="the count aHB! announces against the values its packets deliver",
    ),
)


#: Added to complete the sensor-role coverage.
COVERAGE: tuple[Fault, ...] = (
    Fault(
        "high-volume-binary-two-digit-count",
        "aHB! replies give a 2-digit count (atttnn instead of atttnnn)."
        " With the count unreadable no packet is asked for, so the packet rules have nothing"
        " to judge, nor has the count aHB!'s metadata records are checked against"
        " (aIHB! answers alike, R-6.2-07), nor are those records read.",
        ("R-5.2-01",),
        rewrite=when(_hb_start, lambda r: replace(r, body=r.body[:4] + r.body[5:])),
        inconclusive=(
            "R-4.1-03",
            "R-5.2-02",
            "R-5.2-03",
            "R-5.2-04",
            "R-5.2-05",
            "R-5.2-07",
            "R-5.2.1-01",
            *UNREAD_RECORDS,
        ),
        needs=("HB",),
    ),
    Fault(
        "binary-size-big-endian",
        "The payload size field of HB packets is sent high byte first."
        " No packet reads as values, so none shows how the values are ordered (R-5.2-07).",
        ("R-5.2-02",),
        rewrite=packet_rewrite(_size_big_endian),
        inconclusive=("R-5.2-07",),
        needs=("HB",),
    ),
    Fault(
        "high-volume-unsupported-silent",
        "A sensor without HA/HB stays silent to aHA!/aHB! instead of answering a000000.",
        ("R-5.4-02",),
        profile=_without_high_volume,
        rewrite=when(_hv_start, silence),
        masks=dict.fromkeys(
            (
                "binary-fewer-values",
                "binary-payload-over-1000",
                "high-volume-binary-two-digit-count",
            ),
            "a sensor without HA and HB has no high-volume reply or packet to spoil",
        ),
        needs=("v1.4",),
    ),
)
