"""Named, composable deviations of the reference sensor (the suite's fault-detection matrix).

A :class:`Fault` changes the emulator through up to three hooks:

- ``settings``: overrides of :class:`~conformance.emulator.behaviour.Behaviour` (timing
  numbers and behaviour switches);
- ``rewrite``: a transform of each :class:`~conformance.emulator.replies.Reply` before it is
  encoded (return None to suppress the reply);
- ``profile``: a transform of the :class:`~conformance.emulator.profile.Profile` (values,
  counts, metadata), so that value-level faults still go through the normal packing.

``violates`` lists the requirement IDs the fault breaks, and only those: for every fault the
suite run against the faulty emulator must FAIL (or WARN, for SHOULD rules and lenient
decisions such as A18) exactly these IDs. Conventions used when choosing them:

- Where the catalogue has a rule for the specific reply type, a fault declares that rule and
  not the general one that also covers it: HA data over 75 characters is R-5.1-03 (not also
  R-4.4-05), R data over 75 is R-4.4.8.1-01, a D reply without CR LF is R-4.2-03 (not also
  the D format rule R-4.4.8-01), a metadata record without units is R-6.2.2-01.
- R-4.4-01 ("a well-formed answer to every basic command") is declared, next to the specific
  rule, only where a basic command gets no answer at all.
- Rewrites of ``atttn`` replies apply to the identify form too, so R-6.1-02 (identify reply
  equals the command's reply) stays intact unless the fault is about that rule.
- A fault applies to the default v1.4 profile unless ``version`` says otherwise.

Faults compose: :func:`compose` applies settings in order (the last one wins on a clash),
chains rewrites in order and applies profile transforms in order.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, fields, replace
from types import MappingProxyType
from typing import Any

from ..protocol.binary import DataType, type_size
from ..protocol.commands import Kind
from ..protocol.crc import ascii_crc, binary_crc
from .behaviour import Behaviour
from .profile import MeasurementSpec, Packet, Profile
from .replies import Reply, ReplyKind

Rewrite = Callable[[Reply], Reply | None]
ProfileTransform = Callable[[Profile], Profile]

_BEHAVIOUR_FIELDS = frozenset(f.name for f in fields(Behaviour))


@dataclass(frozen=True)
class Fault:
    """One deviation: what it does, which requirements it breaks, and how."""

    name: str
    description: str
    violates: tuple[str, ...]
    settings: Mapping[str, Any] = field(default_factory=dict)
    rewrite: Rewrite | None = None
    profile: ProfileTransform | None = None
    version: str = "14"
    #: Requirements the fault honestly leaves undecided (the description says why); the
    #: matrix demands exactly these INCONCLUSIVE, so collateral is declared, never ignored.
    inconclusive: tuple[str, ...] = ()
    #: What the maker's declaration says where it differs from the clean profile (say, the
    #: names of its extended commands). On ``sim`` the declaration is the clean profile's:
    #: a fault is caught from the wire, never from names the tool was handed by the fault.
    declares: ProfileTransform | None = None

    def __post_init__(self) -> None:
        if not self.violates:
            raise ValueError(f"fault {self.name} declares no requirement")
        if set(self.violates) & set(self.inconclusive):
            raise ValueError(f"fault {self.name}: a requirement cannot be broken and undecided")
        unknown = set(self.settings) - _BEHAVIOUR_FIELDS
        if unknown:
            raise ValueError(f"fault {self.name}: unknown settings {sorted(unknown)}")
        if not (self.settings or self.rewrite or self.profile):
            raise ValueError(f"fault {self.name} changes nothing")
        object.__setattr__(self, "settings", MappingProxyType(dict(self.settings)))


@dataclass(frozen=True)
class FaultSet:
    """Several faults applied together."""

    faults: tuple[Fault, ...] = ()
    behaviour: Behaviour = field(default_factory=Behaviour)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.faults)

    @property
    def violates(self) -> tuple[str, ...]:
        seen: dict[str, None] = {}
        for fault in self.faults:
            seen.update(dict.fromkeys(fault.violates))
        return tuple(seen)

    def rewrite(self, reply: Reply) -> Reply | None:
        current: Reply | None = reply
        for fault in self.faults:
            if current is None:
                return None
            if fault.rewrite is not None:
                current = fault.rewrite(current)
        return current

    def apply_profile(self, profile: Profile) -> Profile:
        for fault in self.faults:
            if fault.profile is not None:
                profile = fault.profile(profile)
        return profile

    def declared_profile(self, clean: Profile) -> Profile:
        """The profile the maker's declaration describes: the clean one, changed only by
        what a fault says its maker declares."""
        for fault in self.faults:
            if fault.declares is not None:
                clean = fault.declares(clean)
        return clean


def compose(names: Iterable[str]) -> FaultSet:
    """The :class:`FaultSet` for fault names (KeyError naming the unknown fault)."""
    chosen = []
    settings: dict[str, Any] = {}
    for name in names:
        if name not in FAULTS:
            raise KeyError(f"unknown fault {name!r}")
        fault = FAULTS[name]
        chosen.append(fault)
        settings.update(fault.settings)
    return FaultSet(tuple(chosen), replace(Behaviour(), **settings))


# -- rewrite helpers ---------------------------------------------------------------------------
def _only(kinds: Iterable[ReplyKind], change: Callable[[Reply], Reply | None]) -> Rewrite:
    wanted = frozenset(kinds)

    def rewrite(reply: Reply) -> Reply | None:
        return change(reply) if reply.kind in wanted else reply

    return rewrite


def _source_kind(reply: Reply) -> Kind | None:
    return reply.source.kind if reply.source is not None else None


def _after(kinds: Iterable[Kind], *, crc: bool | None = None) -> Callable[[Reply], bool]:
    """Match D replies whose measurement was one of ``kinds`` (and a CRC variant or not)."""
    wanted = frozenset(kinds)

    def match(reply: Reply) -> bool:
        if reply.kind is not ReplyKind.DATA or _source_kind(reply) not in wanted:
            return False
        return crc is None or (reply.source is not None and reply.source.crc == crc)

    return match


def _when(match: Callable[[Reply], bool], change: Callable[[Reply], Reply | None]) -> Rewrite:
    def rewrite(reply: Reply) -> Reply | None:
        return change(reply) if match(reply) else reply

    return rewrite


def _has_values(reply: Reply) -> bool:
    return len(reply.body) > 1


def _set(**changes: Any) -> Callable[[Reply], Reply]:
    return lambda reply: replace(reply, **changes)


def _silence(reply: Reply) -> None:
    return None


def _wrong_crc(reply: Reply) -> Reply:
    good = ascii_crc(reply.body)
    return replace(reply, crc_text=good[:2] + chr(0x40 | ((ord(good[2]) + 1) & 0x3F)))


def _measure_family(reply: Reply, digits: int) -> bool:
    return reply.kind in (ReplyKind.START, ReplyKind.IDENTIFY) and reply.digits == digits


def _start_with(digits: int, change: Callable[[str], str]) -> Rewrite:
    def rewrite(reply: Reply) -> Reply:
        if _measure_family(reply, digits):
            return replace(reply, body=change(reply.body))
        return reply

    return rewrite


def _bump_count(body: str) -> str:
    last = int(body[-1])
    return body[:-1] + str(last + 1 if last < 9 else last - 1)


def _vary_repeat(reply: Reply) -> Reply:
    if reply.repeat == 0 or not _has_values(reply):
        return reply
    match = re.search(r"[0-9](?=[^0-9]*$)", reply.body)
    if match is None:
        return reply
    i = match.start()
    digit = str((int(reply.body[i]) + reply.repeat) % 10)
    return replace(reply, body=reply.body[:i] + digit + reply.body[i + 1 :])


def _binary(change: Callable[[Reply], None]) -> Rewrite:
    def rewrite(reply: Reply) -> Reply:
        if reply.kind is ReplyKind.BINARY and reply.binary is not None:
            reply = replace(reply, binary=replace(reply.binary))
            change(reply)
        return reply

    return rewrite


def _binary_crc_wrong(reply: Reply) -> None:
    assert reply.binary is not None
    parts = reply.binary
    good = _packet_crc(parts.address, parts.dtype, parts.payload)
    parts.crc = bytes((good[0] ^ 0x01, good[1]))


def _binary_crc_swapped(reply: Reply) -> None:
    assert reply.binary is not None
    parts = reply.binary
    good = _packet_crc(parts.address, parts.dtype, parts.payload)
    if good[0] == good[1]:  # swapping would change nothing; flip a bit so it still shows
        good = bytes((good[0] ^ 0x01, good[1]))
    parts.crc = bytes((good[1], good[0]))


def _packet_crc(address: int, dtype: int, payload: bytes) -> bytes:
    head = bytes([address]) + len(payload).to_bytes(2, "little") + bytes([dtype])
    return binary_crc(head + payload)


def _binary_first_packet(change: Callable[[Reply], None]) -> Callable[[Reply], None]:
    """Apply ``change`` to the DB0 packet only (when it carries data)."""

    def apply(reply: Reply) -> None:
        first = reply.command is not None and reply.command.index == 0
        if first and reply.binary is not None and reply.binary.payload:
            change(reply)

    return apply


def _pad_payload(reply: Reply) -> None:
    """One stray byte after the values of a multi-byte type (an int8 payload cannot show it)."""
    assert reply.binary is not None
    if reply.binary.payload and type_size(reply.binary.dtype) > 1:
        reply.binary.payload += b"\x00"


def _invalid_type(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.dtype = 11


def _parity_address(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.address |= 0x80


# -- helpers for the faults added with the sensor-role coverage --------------------------------
def _one_line_extended(reply: Reply) -> bool:
    return (
        reply.kind is ReplyKind.EXTENDED
        and reply.command is not None
        and (reply.command.body == "XSN")
    )


def _later_m2_data(reply: Reply) -> bool:
    source, cmd = reply.source, reply.command
    return (
        reply.kind is ReplyKind.DATA
        and source is not None
        and cmd is not None
        and source.kind is Kind.MEASURE
        and source.group == 2
        and cmd.index >= 1
    )


def _plain_c(reply: Reply) -> bool:
    cmd = reply.command
    return (
        reply.kind is ReplyKind.START
        and cmd is not None
        and cmd.kind is Kind.CONCURRENT
        and not cmd.crc
        and cmd.group == 0
    )


def _verify_sr(reply: Reply) -> bool:
    return reply.kind is ReplyKind.SERVICE_REQUEST and _source_kind(reply) is Kind.VERIFY


def _crc_high_bits(reply: Reply) -> Reply:
    """The three CRC characters with 0x60 instead of 0x40 or'ed in (R-4.4.12-06)."""
    if not reply.crc:
        return reply
    good = ascii_crc(reply.body)
    return replace(reply, crc_text="".join(chr(ord(c) | 0x20) for c in good))


def _hb_start(reply: Reply) -> bool:
    return _measure_family(reply, 3) and _source_kind(reply) is Kind.HIGH_VOLUME_BINARY


def _hv_start(reply: Reply) -> bool:
    return reply.kind is ReplyKind.START and _source_kind(reply) in (
        Kind.HIGH_VOLUME_ASCII,
        Kind.HIGH_VOLUME_BINARY,
    )


def _size_big_endian(reply: Reply) -> None:
    assert reply.binary is not None
    reply.binary.size_order = "big"


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
    fields[1] = fields[1] + ";x"


def _long_identifier(fields: list[str]) -> None:
    fields[0] = "LONGIDENTIFIER"


def _without_high_volume(profile: Profile) -> Profile:
    keep = {k: v for k, v in profile.measurements.items() if k not in ("HA", "HB")}
    return replace(profile, measurements=keep)


def _rename_extended(profile: Profile) -> Profile:
    """Extended commands without the recommended X (still not a basic command letter)."""
    return replace(profile, extended={"Z" + k[1:]: v for k, v in profile.extended.items()})


def _long_help_line(profile: Profile) -> Profile:
    extended = dict(profile.extended)
    extended["XHELP"] = extended["XHELP"] + "\n" + "L" * 80
    return replace(profile, extended=extended)


def _overstated_ttt(spec: MeasurementSpec) -> MeasurementSpec:
    return replace(spec, ttt=10)


def _fresh_address_one(profile: Profile) -> Profile:
    return replace(profile, address="1")


def _address_quiet_2s(profile: Profile) -> Profile:
    return replace(profile, address_change_quiet=2.0)


# -- profile helpers ---------------------------------------------------------------------------
def _last_record_dropped(spec: MeasurementSpec) -> MeasurementSpec:
    return replace(spec, metadata=spec.metadata[:-1])


def _with_spec(key: str, change: Callable[[MeasurementSpec], MeasurementSpec]) -> ProfileTransform:
    def transform(profile: Profile) -> Profile:
        measurements = dict(profile.measurements)
        measurements[key] = change(measurements[key])
        return replace(profile, measurements=measurements)

    return transform


def _first_value(new: str) -> Callable[[MeasurementSpec], MeasurementSpec]:
    return lambda spec: replace(spec, values=(new, *spec.values[1:]))


def _extra_meta(spec: MeasurementSpec) -> tuple[tuple[str, ...], ...]:
    return (*spec.metadata, ("XX", " ", "extra"))


def _long_record(spec: MeasurementSpec) -> MeasurementSpec:
    first = spec.metadata[0]
    return replace(spec, metadata=((*first, "x" * 70), *spec.metadata[1:]))


def _units_dropped(spec: MeasurementSpec) -> MeasurementSpec:
    return replace(spec, metadata=tuple(fields[:1] for fields in spec.metadata))


def _long_continuous(spec: MeasurementSpec) -> MeasurementSpec:
    """R0 with 82 value characters; metadata grows along so only the length deviates."""
    extra = ("+1234.567",) * 8
    metadata = (*spec.metadata, *(("XL", " ") for _ in extra))
    return replace(spec, values=spec.values + extra, metadata=metadata)


def _crc_twin(profile: Profile) -> Profile:
    plain = profile.measurements["M"]
    twin = replace(plain, values=plain.values[:-1], metadata=plain.metadata[:-1])
    return replace(profile, measurements={**profile.measurements, "MC": twin})


def _big_packet(spec: MeasurementSpec) -> MeasurementSpec:
    packet = Packet(DataType.UINT16, tuple(range(501)))  # 1002 payload bytes
    metadata = (*spec.metadata, *(("XB", " ") for _ in range(501)))
    return replace(spec, packets=(*spec.packets, packet), metadata=metadata)


def _v13_wide_concurrent(spec: MeasurementSpec) -> MeasurementSpec:
    values = tuple(f"+{i}" for i in range(25))
    return replace(spec, values=values, metadata=tuple(("XC", " ") for _ in values))


# -- the registry -------------------------------------------------------------------------------
_DATA = (ReplyKind.DATA,)
_M_FAMILY = (Kind.MEASURE, Kind.VERIFY)
_C_FAMILY = (Kind.CONCURRENT,)


def _faults() -> list[Fault]:
    return [
        # -- identification and reply format ---------------------------------------------------
        Fault(
            "ident-optional-too-long",
            "aI! carries a 14-character optional field, making the reply 34 characters.",
            ("R-4.4.2-01",),
            rewrite=_only(
                [ReplyKind.IDENTIFICATION], lambda r: replace(r, body=r.body + "EXTRA.ME")
            ),
        ),
        Fault(
            "ident-truncated",
            "aI! stops after the model field: sensor version and optional field are missing.",
            ("R-4.4.2-01",),
            rewrite=_only([ReplyKind.IDENTIFICATION], lambda r: replace(r, body=r.body[:17])),
        ),
        Fault(
            "ident-bad-version",
            "aI! gives the SDI-12 version as 'V4' instead of two digits.",
            ("R-4.4.2-02",),
            rewrite=_only(
                [ReplyKind.IDENTIFICATION], lambda r: replace(r, body=r.body[0] + "V4" + r.body[3:])
            ),
        ),
        Fault(
            "ack-trailing-space",
            "a! answers 'a <CR><LF>' with a space after the address.",
            ("R-4.4.1-01",),
            rewrite=_only([ReplyKind.ACKNOWLEDGE], lambda r: replace(r, body=r.body + " ")),
        ),
        Fault(
            "measure-ttt-two-digits",
            "M/MC/Mn/V replies give ttt with two digits (atttn becomes attn)."
            " No measurement reply parses, so no data are there for the identify commands to"
            " disturb (R-6.1-03).",
            ("R-4.4.5-01",),
            rewrite=_start_with(1, lambda body: body[0] + body[2:]),
            inconclusive=("R-6.1-03",),
        ),
        Fault(
            "measure-count-zero",
            "aM!/aMC! announce n = 0 for the defined measurement and deliver no values.",
            ("R-4.4.5-02",),
            profile=_with_spec("M", lambda s: replace(s, values=(), metadata=())),
        ),
        Fault(
            "concurrent-three-digit-count",
            "C/CC/Cn replies give a 3-digit count (atttnnn instead of atttnn).",
            ("R-4.4.7-01",),
            rewrite=_start_with(2, lambda body: body[:4] + "0" + body[4:]),
        ),
        Fault(
            "concurrent-zero",
            "aC!/aCC! answer a00000 (no values) for the plain concurrent measurement.",
            ("R-4.4.7-02",),
            profile=_with_spec("C", lambda s: replace(s, values=(), metadata=(), ttt=0)),
        ),
        Fault(
            "high-volume-two-digit-count",
            "HA replies give a 2-digit count (atttnn instead of atttnnn)."
            " With the count unreadable no D data are asked for, so the aHA! data rules have"
            " nothing to judge.",
            ("R-5.1-01",),
            rewrite=_when(
                lambda r: _measure_family(r, 3) and _source_kind(r) is Kind.HIGH_VOLUME_ASCII,
                lambda r: replace(r, body=r.body[:4] + r.body[5:]),
            ),
            inconclusive=("R-5.1-02", "R-5.1-03"),
        ),
        Fault(
            "value-missing-sign",
            "The first value of aM! has no sign ('22.15' instead of '+22.15').",
            ("R-4.4.8-02",),
            profile=_with_spec("M", _first_value("22.15")),
        ),
        Fault(
            "value-eight-digits",
            "The first value of aM! has eight digits ('+12345678').",
            ("R-4.4.8-02",),
            profile=_with_spec("M", _first_value("+12345678")),
        ),
        Fault(
            "value-ten-chars",
            "The first value of aM! is ten characters long ('+12345.678').",
            ("R-4.4.8-02",),
            profile=_with_spec("M", _first_value("+12345.678")),
        ),
        Fault(
            "value-two-points",
            "The first value of aM! has two decimal points ('+22.1.5').",
            ("R-4.4.8-02",),
            profile=_with_spec("M", _first_value("+22.1.5")),
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
        ),
        Fault(
            "continuous-over-75",
            "aR0!/aRC0! return 82 value characters.",
            ("R-4.4.8.1-01",),
            profile=_with_spec("R0", _long_continuous),
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
            rewrite=_only(_DATA, _set(end="")),
        ),
        Fault(
            "non-printable-char",
            "The extended command's reply contains a BEL (0x07) character.",
            ("R-4.2-02",),
            rewrite=_only([ReplyKind.EXTENDED], lambda r: replace(r, body=r.body + "\x07")),
        ),
        Fault(
            "wrong-reply-address",
            "D replies start with the next address instead of the sensor's own.",
            ("R-4.3-01",),
            rewrite=_only(
                _DATA, lambda r: replace(r, body=("1" if r.body[0] != "1" else "2") + r.body[1:])
            ),
        ),
        Fault(
            "parity-error",
            "The LF of every a! reply is sent with odd parity.",
            ("R-4.1-02",),
            rewrite=_only([ReplyKind.ACKNOWLEDGE], _set(flip_parity=(-1,))),
        ),
        Fault(
            "extended-no-crlf",
            "The one-line extended command's reply (aXSN!) ends without CR LF.",
            ("R-4.4.13-01", "R-4.2-03"),
            rewrite=_when(_one_line_extended, _set(end="")),
        ),
        # -- CRC ---------------------------------------------------------------------------------
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
            rewrite=_when(_after([Kind.MEASURE, Kind.CONCURRENT], crc=True), _set(crc=False)),
        ),
        Fault(
            "high-volume-crc-missing",
            "D replies after HA carry no CRC.",
            ("R-5.1-03",),
            rewrite=_when(_after([Kind.HIGH_VOLUME_ASCII]), _set(crc=False)),
        ),
        Fault(
            "crc-on-plain",
            "D replies after plain M/Mn/V/C/Cn carry a CRC.",
            ("R-4.4.12-03",),
            rewrite=_when(_after([*_M_FAMILY, *_C_FAMILY], crc=False), _set(crc=True)),
        ),
        Fault(
            "crc-on-continuous",
            "aRn! replies (no CRC requested) carry a CRC.",
            ("R-4.4.12-03",),
            rewrite=_when(
                lambda r: r.kind is ReplyKind.CONTINUOUS and not r.crc and _has_values(r),
                _set(crc=True),
            ),
        ),
        Fault(
            "continuous-crc-missing",
            "aRCn! replies for supported Rn carry no CRC.",
            ("R-4.4.12-02",),
            rewrite=_when(
                lambda r: r.kind is ReplyKind.CONTINUOUS and r.crc and _has_values(r),
                _set(crc=False),
            ),
        ),
        Fault(
            "unsupported-rc-without-crc",
            "aRCn! for an unsupported n answers 'a<CR><LF>' instead of 'a<CRC><CR><LF>'.",
            ("R-4.4.8.1-03", "R-4.4.12-02"),
            rewrite=_when(
                lambda r: r.kind is ReplyKind.CONTINUOUS and r.crc and not _has_values(r),
                _set(crc=False),
            ),
        ),
        Fault(
            "metadata-crc-missing",
            "Metadata replies for CRC commands (aIMC_nnn!, aICC_nnn!, aIHA_nnn!...) lack the CRC.",
            ("R-6.2-02",),
            rewrite=_when(
                lambda r: r.kind is ReplyKind.METADATA and r.crc and _has_values(r),
                _set(crc=False),
            ),
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
            rewrite=_binary(_binary_crc_wrong),
        ),
        Fault(
            "binary-crc-big-endian",
            "High-volume binary packets send the CRC high byte first.",
            ("R-5.2-03",),
            rewrite=_binary(_binary_crc_swapped),
        ),
        # -- service requests --------------------------------------------------------------------
        Fault(
            "no-service-request",
            "M/MC/Mn/V with ttt > 0 never send a service request (data are ready before ttt)."
            " With no service request its form and timing cannot be judged, nor can a break be"
            " shown to abort one (R-4.4.5.1-01).",
            ("R-4.4.6-02",),
            settings={"service_request": False},
            inconclusive=("R-4.4.5-09", "R-4.4.5.1-01", "R-4.4.6-01", "R-4.4.6-04"),
        ),
        Fault(
            "late-service-request",
            "The service request comes 0.25 s after ttt expired (data were ready in time).",
            ("R-4.4.6-04",),
            settings={"service_request_late": 0.25},
        ),
        Fault(
            "service-request-after-ttt-zero",
            "M/V answered with ttt = 000 still send a service request right after the reply.",
            ("R-4.4.6-03",),
            settings={"service_request_on_ttt_zero": True},
        ),
        Fault(
            "concurrent-service-request",
            "C/CC/Cn/HA/HB send a service request when their data are ready.",
            ("R-4.4.6-05", "R-4.4.7-04", "R-5.3-01"),
            settings={"service_request_on_concurrent": True},
        ),
        Fault(
            "service-request-extra-chars",
            "The service request is 'aSR<CR><LF>' instead of 'a<CR><LF>'."
            " The service request is not recognised, so a break cannot be shown to prevent one"
            " (R-4.4.5.1-01).",
            ("R-4.4.6-01",),
            rewrite=_only([ReplyKind.SERVICE_REQUEST], lambda r: replace(r, body=r.body + "SR")),
            inconclusive=("R-4.4.5.1-01",),
        ),
        Fault(
            "chatter-before-service-request",
            "Halfway between atttn and the service request the sensor sends 'aBUSY<CR><LF>'.",
            ("R-4.4.5-08",),
            settings={"chatter_before_service_request": True},
        ),
        Fault(
            "identify-sends-service-request",
            "aIM!/aIV! (and numbered forms) are followed by a service request as if measuring.",
            ("R-6.1-03",),
            settings={"service_request_on_identify": True},
        ),
        # -- aborts ------------------------------------------------------------------------------
        Fault(
            "break-does-not-abort-measure",
            "A break during M/V keeps the measurement running; SR and data follow as usual.",
            ("R-4.4.5.1-01",),
            settings={"break_aborts_measure": False},
        ),
        Fault(
            "abort-keeps-old-data",
            "After an abort, D returns the data of the measurement before the aborted one.",
            ("R-4.4.5.1-02", "R-4.4.7.1-02", "R-4.4.7.1-01", "R-5.3-01"),
            settings={"abort_keeps_old_data": True},
        ),
        Fault(
            "no-recovery-after-abort",
            "After an abort the sensor ignores everything until the next break after the "
            "aborting one.",
            ("R-4.4.5.1-03",),
            settings={"deaf_after_abort": True},
        ),
        Fault(
            "break-aborts-concurrent",
            "A break aborts a running C/CC/HA/HB measurement (D then returns nothing).",
            ("R-4.4.7-05", "R-5.3-01"),
            settings={"break_aborts_concurrent": True},
        ),
        Fault(
            "foreign-command-aborts-concurrent",
            "A command to another address aborts a running C/CC/HA/HB measurement.",
            ("R-4.4.7-05", "R-5.3-01"),
            settings={"foreign_aborts_concurrent": True},
        ),
        Fault(
            "concurrent-not-aborted",
            "A valid command to the sensor does not abort its running concurrent measurement.",
            ("R-4.4.7.1-01", "R-4.4.7.1-02", "R-5.3-01"),
            settings={"command_aborts_concurrent": False},
        ),
        # -- data buffer -------------------------------------------------------------------------
        Fault(
            "buffer-cleared-by-break",
            "Once all D pages were read, the next break empties the data buffer."
            " Data that do not survive a plain re-read leave nothing for the identify commands"
            " to disturb (R-6.1-03).",
            ("R-4.4.5-10",),
            settings={"clear_on_break_after_read": True},
            inconclusive=("R-6.1-03",),
        ),
        Fault(
            "buffer-cleared-after-read",
            "Once all D pages were read, the buffer is empty (repeated D returns nothing)."
            " Data that do not survive a plain re-read leave nothing for the identify commands"
            " to disturb (R-6.1-03).",
            ("R-4.4.5-10",),
            settings={"clear_after_read": True},
            inconclusive=("R-6.1-03",),
        ),
        Fault(
            "data-changes-on-repeat",
            "A repeated Dn returns the last digit changed."
            " Data that do not survive a plain re-read leave nothing for the identify commands"
            " to disturb (R-6.1-03).",
            ("R-4.4.5-10",),
            rewrite=_only(_DATA, _vary_repeat),
            inconclusive=("R-6.1-03",),
        ),
        Fault(
            "data-lost-after-standby",
            "Once all D pages were read, entering standby empties the data buffer."
            " Data that do not survive a plain re-read leave nothing for the identify commands"
            " to disturb (R-6.1-03).",
            ("R-4.4.5-10",),
            settings={"clear_on_standby_after_read": True},
            inconclusive=("R-6.1-03",),
        ),
        Fault(
            "identify-clears-buffer",
            "Identify-measurement commands (aIM!, aIC!...) empty the data buffer.",
            ("R-6.1-03",),
            settings={"identify_clears_data": True},
        ),
        # -- addressing --------------------------------------------------------------------------
        Fault(
            "answers-foreign-address",
            "a! and aI! are answered for every address (with that address), then standby.",
            ("R-4.0-01", "R-4.4.4-03"),
            settings={"answer_foreign": True},
        ),
        Fault(
            "ignores-query",
            "?! gets no answer.",
            ("R-4.4.3-01", "R-4.4-01"),
            settings={"answer_query": False},
        ),
        Fault(
            "address-change-not-applied",
            "aAb! answers b but the sensor keeps its old address.",
            ("R-4.4.4-01", "R-4.4.4-03", "R-4.3-03"),
            settings={"apply_address_change": False},
        ),
        Fault(
            "answers-old-address",
            "After aAb! the sensor answers at b and still at its old address.",
            ("R-4.4.4-03", "R-4.0-01"),
            settings={"answer_old_address": True},
        ),
        Fault(
            "address-change-wrong-reply",
            "aAb! changes the address but answers with the old one.",
            ("R-4.4.4-01", "R-4.3-03"),
            rewrite=_only(
                [ReplyKind.CHANGE_ADDRESS],
                lambda r: replace(r, body=r.command.address if r.command else r.body),
            ),
        ),
        # -- counts ------------------------------------------------------------------------------
        Fault(
            "fewer-values-than-announced",
            "aM! announces 3 values but D returns 2.",
            ("R-4.4.8-03",),
            profile=_with_spec("M", lambda s: replace(s, values=s.values[:-1], announced=3)),
        ),
        Fault(
            "more-values-than-announced",
            "aM! announces 3 values but D returns 4.",
            ("R-4.4.8-03",),
            profile=_with_spec("M", lambda s: replace(s, values=(*s.values, "+1"), announced=3)),
        ),
        Fault(
            "d0-empty",
            "Completed measurements hold no values: D0 answers 'a<CR><LF>'."
            " With no values delivered, neither a disturbed concurrent measurement (R-4.4.7-05)"
            " nor data the identify commands could disturb (R-6.1-03) can be compared.",
            ("R-4.4.8-04", "R-4.4.8-03", "R-4.4.5-03", "R-5.2-07"),
            settings={"drop_all_values": True},
            inconclusive=("R-4.4.7-05", "R-6.1-03"),
        ),
        Fault(
            "undefined-measure-silent",
            "Undefined aMn!/aMCn! get no answer instead of a0000.",
            ("R-4.4.9-01", "R-4.4.9-02", "R-4.4-01", "R-4.4.12-01", "R-6.1-01"),
            settings={"answer_undefined_measure": False},
        ),
        Fault(
            "undefined-concurrent-silent",
            "Undefined aCn!/aCCn! get no answer instead of a00000.",
            ("R-4.4.10-01", "R-4.4.10-02", "R-4.4-01", "R-4.4.12-01", "R-6.1-01"),
            settings={"answer_undefined_concurrent": False},
        ),
        Fault(
            "high-volume-stops-at-d9",
            "After HA, aD10! and higher get no answer, so values past D9 cannot be read.",
            ("R-5.1-02", "R-4.4.8-03"),
            settings={"max_data_index": 9},
        ),
        Fault(
            "continuous-needs-r0-first",
            "aRn! (n > 0) answers as unsupported unless aR0! was the previous command.",
            ("R-4.4.8.1-02",),
            settings={"continuous_needs_r0": True},
        ),
        # -- metadata ----------------------------------------------------------------------------
        Fault(
            "metadata-missing-units",
            "Metadata records of aM! values carry only field 1 (no units field).",
            ("R-6.2.2-01",),
            profile=_with_spec("M", _units_dropped),
        ),
        Fault(
            "metadata-too-long",
            "The metadata record of aM!'s first value is over 75 characters.",
            ("R-6.2-04",),
            profile=_with_spec("M", _long_record),
        ),
        Fault(
            "metadata-no-invalid-index-reply",
            "Metadata commands for index 000 or past the count get no answer.",
            ("R-6.2-05", "R-6.2-06"),
            settings={"metadata_invalid_reply": False},
        ),
        Fault(
            "metadata-missing-record",
            "aIM_002! answers as if the index were invalid, though aM! has 3 values.",
            ("R-6.2-07",),
            rewrite=_when(
                lambda r: (
                    r.kind is ReplyKind.METADATA
                    and r.command is not None
                    and r.command.param == 2
                    and _source_kind(r) is Kind.MEASURE
                    and r.source is not None
                    and r.source.group == 0
                ),
                lambda r: replace(r, body=r.body[0]),
            ),
        ),
        Fault(
            "identify-reply-differs",
            "Identify-measurement replies announce a different count than the command does.",
            ("R-6.1-02",),
            rewrite=_only([ReplyKind.IDENTIFY], lambda r: replace(r, body=_bump_count(r.body))),
        ),
        Fault(
            "identify-unsupported",
            "Identify-measurement commands (aIM!, aIC!, aIHA!...) get no answer."
            " With no identify reply there is none to compare with the measurement's (R-6.1-02).",
            ("R-6.1-01",),
            settings={"answer_identify_measurement": False},
            inconclusive=("R-6.1-02",),
        ),
        # -- high-volume binary -------------------------------------------------------------------
        Fault(
            "binary-payload-not-multiple",
            "Packets of multi-byte types carry one stray byte after their values."
            " No packet reads as values, so none shows how the values are ordered (R-5.2-07).",
            ("R-5.2-05",),
            rewrite=_binary(_pad_payload),
            inconclusive=("R-5.2-07",),
        ),
        Fault(
            "binary-invalid-type",
            "DB0's packet carries data type code 11."
            " No packet reads as values, so none shows how the values are ordered (R-5.2-07).",
            ("R-5.2.1-01",),
            rewrite=_binary(_binary_first_packet(_invalid_type)),
            inconclusive=("R-5.2-07",),
        ),
        Fault(
            "binary-no-empty-packet",
            "aDBn! past the data gets no answer instead of the 6-byte empty packet.",
            ("R-5.2-06",),
            settings={"empty_packet": False},
        ),
        Fault(
            "binary-payload-over-1000",
            "HB adds an eleventh packet of 501 uint16 values: 1002 payload bytes.",
            ("R-5.2-04",),
            profile=_with_spec("HB", _big_packet),
        ),
        Fault(
            "binary-address-parity",
            "The address byte of DB packets carries a parity bit in bit 7 (not 8N1).",
            ("R-4.1-03",),
            rewrite=_binary(_parity_address),
        ),
        Fault(
            "binary-fewer-values",
            "aHB! announces one value more than the DB packets deliver.",
            ("R-5.2-07",),
            profile=_with_spec(
                "HB", lambda s: replace(s, announced=s.count + 1, metadata=_extra_meta(s))
            ),
        ),
        # -- timing ------------------------------------------------------------------------------
        Fault(
            "response-too-early",
            "Replies start 5 ms after the command's last stop bit (limit 7.93 ms).",
            ("R-7.0-09",),
            settings={"reply_delay": 5e-3},
        ),
        Fault(
            "response-too-late",
            "Replies start 20 ms after the command's last stop bit (limit 15.40 ms).",
            ("R-7.0-10",),
            settings={"reply_delay": 20e-3},
        ),
        Fault(
            "inter-char-gap",
            "3 ms of marking between reply characters (limit 1.66 ms)."
            " No two reply characters come back to back, so the bit rate cannot be told from the"
            " gaps (R-4.1-01).",
            ("R-7.0-12",),
            settings={"char_gap": 3e-3},
            inconclusive=("R-4.1-01",),
        ),
        Fault(
            "ignores-short-breaks",
            "Spacing under 12.9 ms is not taken as a break (a 12.5 ms break goes unseen).",
            ("R-7.0-04",),
            settings={"break_threshold": 12.9e-3},
        ),
        Fault(
            "wakes-on-short-spacing",
            "Spacing of 4 ms or more counts as a break, so a 5 ms pulse wakes the sensor.",
            ("R-7.0-03",),
            settings={"break_threshold": 4e-3},
        ),
        Fault(
            "early-address",
            "An address right after the break is accepted (no 8.33 ms of marking needed).",
            ("R-7.0-05",),
            settings={"address_marking": 0.0},
        ),
        Fault(
            "late-address-after-break",
            "After a break the sensor needs 20 ms of marking before it looks for an address.",
            ("R-7.0-05",),
            settings={"address_marking": 20e-3},
        ),
        Fault(
            "slow-wake",
            "The sensor needs 110 ms after a break before it can see a start bit.",
            ("R-7.0-07", "R-7.0-05"),
            settings={"wake_delay": 110e-3},
        ),
        Fault(
            "standby-ignored",
            "The sensor never drops to standby by itself: it answers after any marking.",
            ("R-7.0-15",),
            settings={"standby_marking": float("inf")},
        ),
        Fault(
            "no-follow-up-without-break",
            "After each reply the sensor needs a break again (follow-ups within 87 ms fail).",
            ("R-7.0-16",),
            settings={"standby_after_reply": True},
        ),
        Fault(
            "deaf-after-service-request",
            "After its service request the sensor needs a break before aD0!.",
            ("R-7.1-02",),
            settings={"standby_after_service_request": True},
        ),
        Fault(
            "partial-command-accepted",
            "Marking inside a command never drops it: a command with an 8.33 ms gap is answered.",
            ("R-AppB-01",),
            settings={"partial_gap": float("inf")},
        ),
        Fault(
            "stays-awake-after-foreign",
            "A command to another address does not send the sensor to standby.",
            ("R-7.0-14",),
            settings={"standby_after_foreign": False},
        ),
        # -- faults that complete the sensor-role coverage ---------------------------------------
        Fault(
            "m2-later-data-silent",
            "After aM2!/aMC2! the sensor answers aD0! but not aD1! and later.",
            ("R-4.4.8-01", "R-4.4.8-03"),
            rewrite=_when(_later_m2_data, _silence),
        ),
        Fault(
            "fast-baud",
            "Replies go out at 1300 baud: each character takes 7.69 ms instead of 8.33 ms.",
            ("R-4.1-01",),
            settings={"char_time": 10 / 1300},
        ),
        Fault(
            "factory-address-not-zero",
            "The sensor ships at address 1 instead of 0 (the simulated unit is fresh).",
            ("R-4.3-02",),
            profile=_fresh_address_one,
        ),
        Fault(
            "accepts-invalid-address",
            "aA$! makes '$' the sensor's address (only 0-9, A-Z, a-z are addresses).",
            ("R-4.3-04",),
            settings={"accept_any_new_address": True},
        ),
        Fault(
            "wildcard-wrong-reply",
            "?I! and other wildcard commands are answered with a bare address.",
            ("R-4.4.3-02",),
            settings={"wildcard_answer": True},
        ),
        Fault(
            "address-change-deaf-2s",
            "After aAb! the sensor ignores every command for 2 s (1 s is allowed).",
            ("R-4.4.4-02",),
            profile=_address_quiet_2s,
        ),
        Fault(
            "ttt-overstated",
            "aM! announces ttt = 10 s but the data are ready (and the SR sent) after 1.5 s.",
            ("R-4.4.5-09",),
            profile=_with_spec("M", _overstated_ttt),
        ),
        Fault(
            "concurrent-unsupported",
            "aC! gets no answer (the CRC and numbered variants still work).",
            ("R-4.4.7-08", "R-4.4-01"),
            rewrite=_when(_plain_c, _silence),
        ),
        Fault(
            "groups-start-at-d1",
            "M/V data start at D1; D0 answers with no values.",
            ("R-4.4.8.3-02", "R-4.4.8-04", "R-4.4.5-03"),
            settings={"groups_from_d1": True},
        ),
        Fault(
            "verify-no-service-request",
            "aV! never sends its service request (aM! does).",
            ("R-4.4.6-02", "R-4.4.11-01"),
            rewrite=_when(_verify_sr, _silence),
        ),
        Fault(
            "crc-wrong-encoding",
            "CRC characters are or'ed with 0x60 instead of 0x40.",
            ("R-4.4.12-06",),
            rewrite=_crc_high_bits,
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
        ),
        Fault(
            "high-volume-binary-two-digit-count",
            "aHB! replies give a 2-digit count (atttnn instead of atttnnn)."
            " With the count unreadable no packet is asked for, so the packet rules have nothing"
            " to judge.",
            ("R-5.2-01",),
            rewrite=_when(_hb_start, lambda r: replace(r, body=r.body[:4] + r.body[5:])),
            inconclusive=(
                "R-4.1-03",
                "R-5.2-02",
                "R-5.2-03",
                "R-5.2-04",
                "R-5.2-05",
                "R-5.2-07",
                "R-5.2.1-01",
            ),
        ),
        Fault(
            "binary-size-big-endian",
            "The payload size field of HB packets is sent high byte first."
            " No packet reads as values, so none shows how the values are ordered (R-5.2-07).",
            ("R-5.2-02",),
            rewrite=_binary(_size_big_endian),
            inconclusive=("R-5.2-07",),
        ),
        Fault(
            "high-volume-unsupported-silent",
            "A sensor without HA/HB stays silent to aHA!/aHB! instead of answering a000000.",
            ("R-5.4-02",),
            profile=_without_high_volume,
            rewrite=_when(_hv_start, _silence),
        ),
        Fault(
            "metadata-silent",
            "Parameter metadata commands (aIM_001! ...) get no answer."
            " With no metadata reply, the rules on its contents have nothing to judge.",
            ("R-6.2-01", "R-6.2-05", "R-6.2-06", "R-6.2-07"),
            rewrite=_only([ReplyKind.METADATA], _silence),
            inconclusive=("R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2.1-01", "R-6.2.2-01"),
        ),
        Fault(
            "metadata-semicolon-in-field",
            "The units field of metadata records contains a ';'.",
            ("R-6.2-03",),
            rewrite=_metadata_field(_semicolon_in_units),
        ),
        Fault(
            "metadata-long-identifier",
            "Field 1 of metadata records is a 14-character name, not a SHEF code.",
            ("R-6.2.1-01",),
            rewrite=_metadata_field(_long_identifier),
        ),
        Fault(
            "inter-char-gap-tolerance",
            "1.9 ms of marking between reply characters: inside 1.66 + 0.40 ms, but that gap "
            "has no tolerance."
            " No two reply characters come back to back, so the bit rate cannot be told from the"
            " gaps (R-4.1-01).",
            ("R-7.0-12", "R-7.0-01"),
            settings={"char_gap": 1.9e-3},
            inconclusive=("R-4.1-01",),
        ),
        # -- deviations found on a third-party sensor (issue 10) ----------------------------------
        Fault(
            "metadata-crc-sticks",
            "After a CRC metadata command (aIMC_001!), D replies of later plain measurements "
            "carry a CRC too.",
            ("R-4.4.12-03",),
            settings={"metadata_crc_sticks": True},
        ),
        Fault(
            "undefined-group-keeps-data",
            "aMn! for an undefined group answers a0000 but leaves the previous measurement's "
            "values in D0.",
            ("R-4.4.8-03",),
            settings={"undefined_group_keeps_data": True},
        ),
        Fault(
            "metadata-r-count-short",
            "aIR0_nnn! describes one value fewer than aR0! returns.",
            ("R-6.2-06",),
            profile=_with_spec("R0", _last_record_dropped),
        ),
        Fault(
            "continuous-overwrites-data",
            "aRn!/aRCn! share the D buffer: after one, the last measurement's D replies are empty.",
            ("R-4.4.5-10",),
            settings={"continuous_overwrites_data": True},
        ),
        Fault(
            "metadata-crc-unasked",
            "Metadata replies of plain commands (aIM_001!) carry a CRC nobody asked for.",
            ("R-6.2-02",),
            rewrite=_when(
                lambda r: r.kind is ReplyKind.METADATA and not r.crc and _has_values(r),
                _set(crc=True),
            ),
        ),
        # -- timing just inside the limits (boundary probes, issue 10) --------------------------
        Fault(
            "standby-after-40ms",
            "The sensor drops to standby 40 ms after its last reply, not 100 ms: a follow-up "
            "without a break at 40..87 ms goes unanswered.",
            ("R-7.0-16",),
            settings={"standby_after_reply_marking": 40e-3},
        ),
        Fault(
            "standby-after-60ms",
            "The sensor drops to standby 60 ms after its last reply, not 100 ms.",
            ("R-7.0-16",),
            settings={"standby_after_reply_marking": 60e-3},
        ),
        Fault(
            "standby-after-108ms",
            "The sensor stays awake for 108 ms of marking (100 ms + 0.40 ms are allowed).",
            ("R-7.0-15",),
            settings={"standby_marking": 108e-3},
        ),
        # -- version specific --------------------------------------------------------------------
        Fault(
            "v13-concurrent-over-20",
            "v1.3 profile: aC! announces and delivers 25 values (the 2000 text allows 20).",
            ("R-4.4.7-03",),
            profile=_with_spec("C", _v13_wide_concurrent),
            version="13",
        ),
    ]


def _registry() -> dict[str, Fault]:
    registry: dict[str, Fault] = {}
    for fault in _faults():
        if fault.name in registry:
            raise ValueError(f"duplicate fault {fault.name}")
        registry[fault.name] = fault
    return registry


#: Every fault by name.
FAULTS: Mapping[str, Fault] = MappingProxyType(_registry())
