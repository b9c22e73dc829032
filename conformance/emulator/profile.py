"""What an emulated sensor is: identification, measurement groups, values, metadata, options.

A profile is plain data so that one emulator class can play any sensor (the golden v1.4 DUT,
a v1.3 sensor, the misbehaving sensors of the recorder role) and so that faults can derive a
deviating sensor by rewriting data instead of patching code.

Measurements are keyed by their command code without address, CRC letter and ``!``: ``M``,
``M1``..``M9``, ``V``, ``C``, ``C1``..``C9``, ``HA``, ``HB``, and ``R0``..``R9`` for continuous
measurements. A CRC variant (``MC1``, ``CC``, ``RC0``) uses the spec of its plain twin unless the
profile defines the CRC key itself (which only a fault should do, R-4.4.12-04).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType

from ..protocol.binary import DataType
from ..protocol.commands import ADDRESS_CHARS, Command, measurement_code_of
from ..protocol.values import format_value
from ..protocol.version import V13, V14, VERSIONS

Number = int | float


def _values(raw: Sequence[str | Number]) -> tuple[str, ...]:
    """Numbers become clean value strings; strings are kept as given, so a fault can put a
    malformed value on the wire (the default profiles are checked for clean values by tests)."""
    return tuple(v if isinstance(v, str) else format_value(v) for v in raw)


@dataclass(frozen=True)
class Packet:
    """One high-volume binary packet's worth of data: a type and its values."""

    dtype: DataType
    values: tuple[Number, ...]


@dataclass(frozen=True)
class MeasurementSpec:
    """One measurement group.

    ``values`` are SDI-12 value strings, sent exactly as given (numbers are converted once,
    here). ``ttt`` is the announced time in seconds;
    ``ready_after`` is when, counted from the end of the ``atttn`` reply, the data are ready
    (and the service request of M/V goes out); it must be below ``ttt`` because the whole
    service request has to fit before ttt expires (R-4.4.6-04). ``metadata`` holds the field
    list of each value (field 1 identifier, field 2 units, optional fields after).
    ``packets`` replaces ``values`` for HB. ``announced`` overrides the count the sensor
    claims; it exists for faults, a clean profile leaves it None.
    """

    values: tuple[str, ...] = ()
    ttt: int = 0
    ready_after: float | None = None
    metadata: tuple[tuple[str, ...], ...] = ()
    packets: tuple[Packet, ...] = ()
    announced: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", _values(self.values))
        object.__setattr__(self, "metadata", tuple(tuple(f) for f in self.metadata))
        if not 0 <= self.ttt <= 999:
            raise ValueError(f"ttt {self.ttt} is not 0..999")
        if self.ready_after is not None and self.ttt and not 0 <= self.ready_after < self.ttt:
            raise ValueError("ready_after must lie inside [0, ttt)")

    @property
    def count(self) -> int:
        """The value count the sensor announces (n / nn / nnn)."""
        if self.announced is not None:
            return self.announced
        if self.packets:
            return sum(len(p.values) for p in self.packets)
        return len(self.values)

    @property
    def ready_delay(self) -> float:
        """Seconds from the end of the ``atttn`` reply until the data are ready."""
        if self.ttt == 0:
            return 0.0
        if self.ready_after is not None:
            return self.ready_after
        return max(0.0, self.ttt - 0.5)


def measurement_key(command: Command, *, crc: bool = False) -> str:
    """The profile key of the measurement ``command`` starts, describes or reads (``M1``...):
    its measurement code, with the C of a CRC twin only when ``crc`` asks for it."""
    target = command.target if command.target is not None else command
    # the code of ``replace(target, crc=crc and target.crc)``, without making that command
    return measurement_code_of(target.kind, crc and target.crc, target.group)


@dataclass(frozen=True)
class Profile:
    """A sensor: identification fields (R-4.4.2-01 widths), measurements and options."""

    address: str = "0"
    version: str = V14
    vendor: str = "CONFORM "
    model: str = "EMU001"
    sensor_version: str = "100"
    optional: str = "SN0001"
    measurements: Mapping[str, MeasurementSpec] = field(default_factory=dict)
    extended: Mapping[str, str] = field(default_factory=dict)
    address_settable: bool = True
    address_change_quiet: float = 0.0

    def __post_init__(self) -> None:
        if self.address not in ADDRESS_CHARS:
            raise ValueError(f"bad address {self.address!r}")
        if self.version not in VERSIONS:
            raise ValueError(f"version must be '13' or '14', not {self.version!r}")
        widths = (("vendor", 8), ("model", 6), ("sensor_version", 3))
        for name, width in widths:
            if len(getattr(self, name)) != width:
                raise ValueError(f"{name} must be exactly {width} characters")
        if len(self.optional) > 13:
            raise ValueError("optional identification field is at most 13 characters")
        object.__setattr__(self, "measurements", MappingProxyType(dict(self.measurements)))
        object.__setattr__(self, "extended", MappingProxyType(dict(self.extended)))

    @property
    def v14(self) -> bool:
        return self.version == V14

    def spec_for(self, command: Command) -> MeasurementSpec | None:
        """The spec behind ``command`` (its CRC twin's if the CRC key is not defined)."""
        specific = self.measurements.get(measurement_key(command, crc=True))
        return specific or self.measurements.get(measurement_key(command))

    def identification(self) -> str:
        """The ``aI!`` reply body after the address."""
        return self.version + self.vendor + self.model + self.sensor_version + self.optional


# -- the built-in sensors ---------------------------------------------------------------------
def _meta(code: str, units: str, *extra: str) -> tuple[str, ...]:
    return (code, units, *extra)


def _series(count: int, start: float, step: float, decimals: int) -> tuple[str, ...]:
    return tuple(format_value(round(start + i * step, decimals), decimals) for i in range(count))


_HB_PACKETS = (
    Packet(DataType.INT8, (-128, -1, 0, 127)),
    Packet(DataType.UINT8, (0, 1, 200, 255)),
    Packet(DataType.INT16, (-32768, -2, 1234, 32767)),
    Packet(DataType.UINT16, (0, 1000, 65535)),
    Packet(DataType.INT32, (-2147483648, 42, 2147483647)),
    Packet(DataType.UINT32, (0, 4000000000, 4294967295)),
    Packet(DataType.INT64, (-(2**63), -5, 2**63 - 1)),
    Packet(DataType.UINT64, (0, 2**64 - 1)),
    Packet(DataType.FLOAT32, (3.140000104904175, -1.0, 0.0, 1024.5)),
    Packet(DataType.FLOAT64, (2.718281828459045, -0.001, 1e300)),
)


def _v14_measurements() -> dict[str, MeasurementSpec]:
    m = MeasurementSpec(
        ("+22.15", "+1013.2", "+45.7"),
        ttt=2,
        ready_after=1.5,
        metadata=(
            _meta("TA", "degC", "air temperature"),
            _meta("PA", "hPa", "barometric pressure"),
            _meta("XR", "%", "relative humidity"),
        ),
    )
    # M1 is immediate (ttt = 0): no service request (R-4.4.6-03), D0 works at once (R-4.4.5-03).
    m1 = MeasurementSpec(
        ("+12.61", "+3.3"), ttt=0, metadata=(_meta("VB", "V", "supply"), _meta("VR", "V"))
    )
    # M2's nine 9-character values need D0, D1 and D2 under the 35-character limit.
    m2_values = ("+1234.567", "-12.34567", "+0.000123", "-999.9999", "+5555.555",
                 "-0.100001", "+76543.21", "-1.234567", "+99.99999")  # fmt: skip
    m2 = MeasurementSpec(
        m2_values,
        ttt=5,
        ready_after=4.0,
        metadata=tuple(_meta(f"XP{i}", " ", f"probe {i}") for i in range(1, 10)),
    )
    v = MeasurementSpec(
        ("+1", "+0", "+12.6"),
        ttt=1,
        ready_after=0.4,
        metadata=(_meta("XS", " ", "status"), _meta("XE", " ", "errors"), _meta("VB", "V")),
    )
    c = MeasurementSpec(
        _series(20, -5.0, 1.25, 2),
        ttt=3,
        ready_after=2.0,
        metadata=tuple(_meta("TW", "degC", f"depth {i} m") for i in range(1, 21)),
    )
    # C9: 99 values of 7 characters; 10 per 75-character reply, so D0..D9 exactly (A2).
    c9 = MeasurementSpec(
        _series(99, 10.0, 0.125, 3),
        ttt=4,
        ready_after=3.0,
        metadata=tuple(_meta("XC", "mm", f"bin {i}") for i in range(1, 100)),
    )
    # HA: 120 values of 9 characters, 8 per reply: D0..D14, past D9 (R-5.1-02).
    ha = MeasurementSpec(
        tuple(format_value(round(1000.0 + i * 1.0625, 3), 3) for i in range(120)),
        ttt=6,
        ready_after=5.0,
        metadata=tuple(_meta("XH", "mV", f"channel {i}") for i in range(1, 121)),
    )
    hb_count = sum(len(p.values) for p in _HB_PACKETS)
    hb = MeasurementSpec(
        packets=_HB_PACKETS,
        ttt=2,
        ready_after=1.0,
        metadata=tuple(_meta("XB", " ", f"sample {i}") for i in range(1, hb_count + 1)),
    )
    r0 = MeasurementSpec(("+22.1", "+45.6"), metadata=(_meta("TA", "degC"), _meta("XR", "%")))
    r1 = MeasurementSpec(("+1013.25",), metadata=(_meta("PA", "hPa", "instantaneous"),))
    return {"M": m, "M1": m1, "M2": m2, "V": v, "C": c, "C9": c9, "HA": ha, "HB": hb,
            "R0": r0, "R1": r1}  # fmt: skip


def _v13_measurements() -> dict[str, MeasurementSpec]:
    full = _v14_measurements()
    c1 = MeasurementSpec(
        _series(12, 0.5, 0.5, 1),
        ttt=2,
        ready_after=1.0,
        metadata=tuple(_meta("XC", " ") for _ in range(12)),
    )
    keep = ("M", "M1", "M2", "V", "C", "R0", "R1")
    return {**{k: full[k] for k in keep}, "C1": c1}


#: Extended commands of the built-in sensor: a one-line serial number, and a multi-line help
#: text (v1.4 2023, 4.4.13.1) whose lines are at most 75 characters.
EXTENDED = {
    "XSN": "EMU-0001",
    "XHELP": "\n".join(
        (
            "CONFORM EMU001 reference SDI-12 sensor emulator",
            "aXSN! serial number; aXHELP! this text",
            "Measurements: M M1 M2 V C C9 R0 R1 HA HB",
        )
    ),
}


def default_profile(version: str = V14) -> Profile:
    """The built-in sensor: every command family of ``version`` with realistic values.

    v1.4: M (3 values, SR after 1.5 s of ttt 2), M1 (ttt 0), M2 (D0..D2), V, C (20 values),
    C9 (99 values through D9), R0/R1, HA (120 values through D14), HB (10 packets covering
    every data type), metadata for every value and one extended command ``aXSN!``.
    v1.3: identification ``13``, no high-volume or metadata, concurrent counts of 20 and less.
    """
    if version == V14:
        measurements = _v14_measurements()
    elif version == V13:
        measurements = _v13_measurements()
    else:
        raise ValueError(f"no default profile for version {version!r}")
    extended = dict(EXTENDED) if version == V14 else {"XSN": EXTENDED["XSN"]}
    return Profile(version=version, measurements=measurements, extended=extended)
