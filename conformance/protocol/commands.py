"""The SDI-12 command grammar of v1.3 and v1.4: parse and format every command form.

A :class:`Command` is a value; :func:`parse_command` turns wire text into one or raises
:class:`CommandError` with a reason, and :meth:`Command.text` gives the canonical wire text.
The same grammar serves the tool recorder (what to send), the emulator (what it heard) and the
recorder-role judges (was the recorder's command well formed).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, replace
from enum import StrEnum
from types import MappingProxyType

ADDRESS_CHARS = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
WILDCARD = "?"


class Kind(StrEnum):
    """Command families; the value is a short stable name used in transcripts and reports."""

    ACKNOWLEDGE = "a!"
    QUERY_ADDRESS = "?!"
    IDENTIFY = "aI!"
    CHANGE_ADDRESS = "aAb!"
    MEASURE = "aM!"
    VERIFY = "aV!"
    CONCURRENT = "aC!"
    HIGH_VOLUME_ASCII = "aHA!"
    HIGH_VOLUME_BINARY = "aHB!"
    CONTINUOUS = "aR!"
    DATA = "aD!"
    BINARY_DATA = "aDB!"
    IDENTIFY_MEASUREMENT = "aI<m>!"
    METADATA = "aI<m>_nnn!"
    EXTENDED = "aX!"


#: Commands that start a measurement and so replace the data buffer (R-4.4.5-10).
MEASUREMENT_KINDS = frozenset(
    {Kind.MEASURE, Kind.VERIFY, Kind.CONCURRENT, Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY}
)
#: Measurements answered with a service request when ttt > 0 (R-4.4.6-02, decision A5).
SERVICE_REQUEST_KINDS = frozenset({Kind.MEASURE, Kind.VERIFY})
#: Measurements that run concurrently: no service request, not aborted by a break (R-4.4.7-05).
CONCURRENT_KINDS = frozenset({Kind.CONCURRENT, Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY})
#: The command codes (after the address) of every measurement the suite asks of a sensor:
#: the M family with V, the C family, high volume, and continuous measurements.
M_FAMILY = ("M", "MC", *(f"M{i}" for i in range(1, 10)), *(f"MC{i}" for i in range(1, 10)), "V")
C_FAMILY = ("C", "CC", *(f"C{i}" for i in range(1, 10)), *(f"CC{i}" for i in range(1, 10)))
HV_FAMILY = ("HA", "HB")
CONTINUOUS = (*(f"RC{i}" for i in range(10)), *(f"R{i}" for i in range(10)))
#: Kinds that an identify-measurement or metadata command may describe.
DESCRIBABLE_KINDS = MEASUREMENT_KINDS | {Kind.CONTINUOUS}
#: High-volume measurements (section 5): their replies always carry a CRC (R-5.1-03,
#: R-5.2-03) and their start replies a three-digit count (R-5.1-01, R-5.2-01).
HIGH_VOLUME_KINDS = frozenset({Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY})
#: Commands a v1.3 sensor does not know (high volume, identify-measurement, metadata).
V14_ONLY_KINDS = frozenset(
    {
        Kind.HIGH_VOLUME_ASCII,
        Kind.HIGH_VOLUME_BINARY,
        Kind.BINARY_DATA,
        Kind.IDENTIFY_MEASUREMENT,
        Kind.METADATA,
    }
)
#: Count digits of the reply that starts each measurement: ``atttn`` (R-4.4.5-01),
#: ``atttnn`` (R-4.4.7-01), ``atttnnn`` (R-5.1-01, R-5.2-01).
COUNT_DIGITS: Mapping[Kind, int] = MappingProxyType(
    {
        Kind.MEASURE: 1,
        Kind.VERIFY: 1,
        Kind.CONCURRENT: 2,
        Kind.HIGH_VOLUME_ASCII: 3,
        Kind.HIGH_VOLUME_BINARY: 3,
    }
)
#: Highest ``aDn!`` index: D0..D9 after M/C/V (R-4.4.8-01), D0..D999 after aHA! (R-5.1-02).
DATA_INDEX_MAX = 9
HIGH_VOLUME_DATA_INDEX_MAX = 999


class CommandError(ValueError):
    """Text that is not a well-formed SDI-12 command; ``reason`` says why, for a finding."""

    def __init__(self, text: str, reason: str) -> None:
        super().__init__(f"{text!r}: {reason}")
        self.text = text
        self.reason = reason


#: the kinds :func:`measurement_code_of` and :func:`described` ask about, as module constants: a
#: member read off the enum goes through its metaclass's ``__getattr__`` hook on Python 3.11 (issue
#: 22, matrix25: ~0.13 us a look)
_MEASURE, _CONCURRENT, _VERIFY = Kind.MEASURE, Kind.CONCURRENT, Kind.VERIFY
_HIGH_VOLUME_ASCII, _HIGH_VOLUME_BINARY = Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY
_CONTINUOUS_KIND, _IDENTIFY_MEASUREMENT = Kind.CONTINUOUS, Kind.IDENTIFY_MEASUREMENT


def measurement_code_of(kind: Kind, crc: bool, group: int) -> str:
    """:attr:`Command.measurement_code` of a command of ``kind`` with ``crc`` and ``group``:
    asked of the same command with another CRC flag (the emulator's profile key, per
    exchange) without making that command."""
    c = "C" if crc else ""
    # compared (``==``, as ``match``'s ``case Kind.X`` does) with module constants, not
    # members read off the enum at every case (its metaclass's hook, Python 3.11: matrix25)
    if kind == _MEASURE:
        return "M" + c + (str(group) if group else "")
    if kind == _CONCURRENT:
        return "C" + c + (str(group) if group else "")
    if kind == _VERIFY:
        return "V"
    if kind == _HIGH_VOLUME_ASCII:
        return "HA"
    if kind == _HIGH_VOLUME_BINARY:
        return "HB"
    if kind == _CONTINUOUS_KIND:
        return "R" + c + str(group)
    raise ValueError(f"{kind} has no measurement code")


@dataclass(frozen=True)
class Command:
    """One SDI-12 command.

    ``group`` is the measurement group (0 for plain ``aM!``/``aC!``, 1-9 for ``aM1!``...) or the
    continuous index of ``aRn!``; ``index`` is the data index of ``aDn!``/``aDBn!``;
    ``target`` is the measurement an identify or metadata command describes; ``param`` is
    the metadata value index (``_001`` -> 1); ``body`` is the text between the address and
    ``!`` of an extended command.
    """

    address: str
    kind: Kind
    crc: bool = False
    group: int = 0
    index: int = 0
    new_address: str = ""
    target: Command | None = None
    param: int = 0
    body: str = ""

    # -- classification -------------------------------------------------------------------
    @property
    def starts_measurement(self) -> bool:
        return self.kind in MEASUREMENT_KINDS

    @property
    def is_concurrent(self) -> bool:
        return self.kind in CONCURRENT_KINDS

    @property
    def returns_crc(self) -> bool:
        """Whether replies tied to this command carry a CRC (HA/HB always do)."""
        return self.crc or self.kind in HIGH_VOLUME_KINDS

    def with_address(self, address: str) -> Command:
        return replace(self, address=address)

    # -- formatting -----------------------------------------------------------------------
    @property
    def measurement_code(self) -> str:
        """``M``, ``MC3``, ``CC``, ``HA``, ``R0``, ``RC5``: the letters after the address."""
        return self._measurement_code()

    def _measurement_code(self) -> str:
        """``M``, ``MC3``, ``CC``, ``HA``, ``R0``, ``RC5``: the letters after the address."""
        return measurement_code_of(self.kind, self.crc, self.group)

    @property
    def code(self) -> str:
        """The command text without address and ``!`` (``M1``, ``D12``, ``IMC_003``...)."""
        match self.kind:
            case Kind.ACKNOWLEDGE | Kind.QUERY_ADDRESS:
                return ""
            case Kind.IDENTIFY:
                return "I"
            case Kind.CHANGE_ADDRESS:
                return "A" + self.new_address
            case Kind.DATA:
                return f"D{self.index}"
            case Kind.BINARY_DATA:
                return f"DB{self.index}"
            case Kind.IDENTIFY_MEASUREMENT:
                assert self.target is not None
                return "I" + self.target._measurement_code()
            case Kind.METADATA:
                assert self.target is not None
                return f"I{self.target._measurement_code()}_{self.param:03d}"
            case Kind.EXTENDED:
                return self.body
        return self._measurement_code()

    def text(self) -> str:
        """Canonical wire text, e.g. ``0MC1!``. Made once per command object (it is frozen,
        and a parsed text gives the same object again): the tool recorder asks it of every
        command it sends, some 1,400 a fault-matrix row (issue 22, matrix18)."""
        made = self.__dict__.get("_text")
        if made is None:
            made = self.__dict__["_text"] = f"{self.address}{self.code}!"
        return made

    def encode(self) -> bytes:
        return self.text().encode("ascii")

    def __str__(self) -> str:
        return self.text()


def described(command: Command) -> Command:
    """The measurement an identify-measurement command stands for (R-6.1-02: its reply has
    the same shape), else ``command`` itself."""
    if command.kind is _IDENTIFY_MEASUREMENT and command.target is not None:
        return command.target
    return command


def count_digits(command: Command) -> int:
    """How many count digits the reply to ``command`` (or to its identify form) carries.

    ValueError for a command that is not answered with ``atttn`` and its wider forms.
    """
    kind = described(command).kind
    if kind not in COUNT_DIGITS:
        raise ValueError(f"{command} is not answered with atttn")
    return COUNT_DIGITS[kind]


def data_index_max(measurement: Command | None) -> int:
    """Highest ``aDn!`` index that can hold data of ``measurement`` (R-4.4.8-01, R-5.1-02)."""
    if measurement is not None and measurement.kind is Kind.HIGH_VOLUME_ASCII:
        return HIGH_VOLUME_DATA_INDEX_MAX
    return DATA_INDEX_MAX


# -- constructors, so callers never spell wire text by hand --------------------------------
def acknowledge(a: str) -> Command:
    return Command(a, Kind.ACKNOWLEDGE)


def query_address() -> Command:
    return Command(WILDCARD, Kind.QUERY_ADDRESS)


def identify(a: str) -> Command:
    return Command(a, Kind.IDENTIFY)


def change_address(a: str, b: str) -> Command:
    return Command(a, Kind.CHANGE_ADDRESS, new_address=b)


def measure(a: str, group: int = 0, crc: bool = False) -> Command:
    return Command(a, Kind.MEASURE, crc=crc, group=group)


def concurrent(a: str, group: int = 0, crc: bool = False) -> Command:
    return Command(a, Kind.CONCURRENT, crc=crc, group=group)


def verify(a: str) -> Command:
    return Command(a, Kind.VERIFY)


def high_volume_ascii(a: str) -> Command:
    return Command(a, Kind.HIGH_VOLUME_ASCII)


def high_volume_binary(a: str) -> Command:
    return Command(a, Kind.HIGH_VOLUME_BINARY)


def continuous(a: str, index: int, crc: bool = False) -> Command:
    return Command(a, Kind.CONTINUOUS, crc=crc, group=index)


def data(a: str, index: int) -> Command:
    return Command(a, Kind.DATA, index=index)


def binary_data(a: str, index: int) -> Command:
    return Command(a, Kind.BINARY_DATA, index=index)


def identify_measurement(target: Command) -> Command:
    if target.kind not in MEASUREMENT_KINDS:
        raise ValueError(f"no identify form for {target}")
    return Command(target.address, Kind.IDENTIFY_MEASUREMENT, target=target)


def metadata(target: Command, param: int) -> Command:
    if target.kind not in DESCRIBABLE_KINDS:
        raise ValueError(f"no metadata form for {target}")
    return Command(target.address, Kind.METADATA, target=target, param=param)


def extended(a: str, body: str) -> Command:
    return Command(a, Kind.EXTENDED, body=body)


# -- parsing -------------------------------------------------------------------------------
_NUMBER = r"(0|[1-9][0-9]{0,2})"  # 0..999, no leading zeros (R-5.1-02)
_MEASUREMENT = re.compile(r"(?P<letter>M|C)(?P<crc>C?)(?P<group>[1-9]?)|(?P<v>V)|H(?P<hv>[AB])")
_CONTINUOUS = re.compile(r"R(?P<crc>C?)(?P<group>[0-9])")
_BASIC_LETTERS = frozenset("MVCDRIAH")


def _parse_measurement(address: str, code: str, allow_continuous: bool) -> Command | None:
    """Parse ``M``, ``MC1``, ``V``, ``CC``, ``HA``... (and ``R0``/``RC0`` if allowed)."""
    m = _MEASUREMENT.fullmatch(code)
    if m:
        if m["v"]:
            return verify(address)
        if m["hv"]:
            return Command(
                address, Kind.HIGH_VOLUME_ASCII if m["hv"] == "A" else Kind.HIGH_VOLUME_BINARY
            )
        kind = Kind.MEASURE if m["letter"] == "M" else Kind.CONCURRENT
        return Command(address, kind, crc=bool(m["crc"]), group=int(m["group"] or 0))
    if allow_continuous:
        r = _CONTINUOUS.fullmatch(code)
        if r:
            return continuous(address, int(r["group"]), crc=bool(r["crc"]))
    return None


def _leading_zero_reason(code: str) -> str | None:
    m = re.fullmatch(r"(DB|D|M|MC|C|CC|R|RC)(0[0-9]+)", code)
    if m:
        return f"index {m[2]} has a leading zero"
    return None


#: what :func:`parse_command` made of each text it was given: the (frozen) command, or the
#: reason it is none. A run parses the same few dozen texts thousands of times (the emulator
#: as it hears them, the view per segment, the bus time per wait); cleared when it grows.
_PARSED: dict[tuple[str, bool], Command | str] = {}
_PARSED_MAX = 4096


def parse_command(text: str | bytes, *, allow_wildcard: bool = False) -> Command:
    """Parse one command (``!`` included). Raises :class:`CommandError` with the reason.

    ``allow_wildcard`` admits ``?`` as the address of commands other than ``?!``
    (R-4.4.3-02: a sensor may accept it); by default only ``?!`` may use it. A text parsed
    before gives the same command object again (commands are frozen), or a new
    :class:`CommandError` with the same reason.
    """
    if isinstance(text, bytes):
        try:
            text = text.decode("ascii")
        except UnicodeDecodeError:
            raise CommandError(repr(text), "contains a non-ASCII byte") from None
    key = (text, allow_wildcard)
    found = _PARSED.get(key)
    if found is None:
        try:
            found = _parse_text(text, allow_wildcard)
        except CommandError as exc:
            found = exc.reason
        if len(_PARSED) >= _PARSED_MAX:
            _PARSED.clear()
        _PARSED[key] = found
    if type(found) is str:
        raise CommandError(text, found)
    return found  # type: ignore[return-value]


def command_or_none(text: str) -> Command | None:
    """:func:`parse_command`'s command, None where ``text`` is no valid command (its reason
    dropped): for readers that only ask which command a text is, if any."""
    try:
        return parse_command(text)
    except CommandError:
        return None


def _parse_text(text: str, allow_wildcard: bool) -> Command:
    """:func:`parse_command` of a text it has not seen (the grammar itself)."""
    if not text:
        raise CommandError(text, "empty")
    bad = next((c for c in text if not 0x20 <= ord(c) <= 0x7E), None)
    if bad is not None:
        raise CommandError(text, f"contains non-printable character 0x{ord(bad):02X}")
    if not text.endswith("!"):
        raise CommandError(text, "does not end with '!'")
    if "!" in text[:-1]:
        raise CommandError(text, "'!' appears before the end")
    address, code = text[0], text[1:-1]
    if address == "!":
        raise CommandError(text, "no address")
    if address == WILDCARD:
        if code == "":
            return query_address()
        if not allow_wildcard:
            raise CommandError(text, "'?' is a wildcard only in '?!'")
    elif address not in ADDRESS_CHARS:
        raise CommandError(text, f"bad address {address!r}")
    if code == "":
        return acknowledge(address)
    if code == "I":
        return identify(address)
    if code[0] not in _BASIC_LETTERS:
        return extended(address, code)
    reason = _leading_zero_reason(code)
    if reason:
        raise CommandError(text, reason)
    if code[0] == "A":
        if len(code) != 2:
            raise CommandError(text, "change address takes exactly one new address")
        if code[1] not in ADDRESS_CHARS:
            raise CommandError(text, f"bad new address {code[1]!r}")
        return change_address(address, code[1])
    if m := re.fullmatch(r"D(B?)" + _NUMBER, code):
        return (binary_data if m[1] else data)(address, int(m[2]))
    if code[0] == "I":
        body, _, param = code[1:].partition("_")
        target = _parse_measurement(address, body, allow_continuous=True)
        if target is None:
            raise CommandError(text, f"unknown identify form 'I{body}'")
        if "_" not in code:
            if target.kind == Kind.CONTINUOUS:
                raise CommandError(text, "continuous commands have no identify form")
            return identify_measurement(target)
        if not re.fullmatch(r"[0-9]{3}", param):
            raise CommandError(text, f"metadata index {param!r} is not three digits")
        return metadata(target, int(param))
    command = _parse_measurement(address, code, allow_continuous=True)
    if command is None:
        raise CommandError(text, f"unknown command form {code!r}")
    return command
