"""The harness line protocol, sans-I/O: formatting the tool's messages, parsing and checking
the harness's replies (specification: ``docs/harness-protocol.md``).

Times are whole microseconds on the tool's virtual clock, bytes two hex digits (the 8 wire bits
between start and stop bit). Every check names the offending line, so a harness bug is reported
as an ERROR of the harness with the line that caused it, never as a verdict about the device.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

VERSION = 1
#: The versions a harness may answer ``hello`` with. Version 2 (the firmware kits, docs/kit.md)
#: adds the frame's measured duration to ``tx`` (``tx START XX DURATION``), so the tool
#: places a frame of the device's own bit time on the line and R-4.1-01 is observed; and it
#: holds the harness to the clock: a ``tx`` planned before now is an ERROR, not "as soon as
#: possible". The tool still greets with ``hello 1``: a version-1 harness sees no change.
VERSIONS = (1, 2)
#: What a harness may add to its version in the ``hello`` answer (``hello 2+batch NAME``):
#: ``batch`` lets the tool send a write's characters in one ``chars`` message (answered
#: ``heard K PLAN``: the harness heard the first K and stopped where its plan would act before
#: the next) and add to ``time T`` when nothing from the tool can start (``time T QUIET``), so
#: the harness wakes itself for any ``wait`` before QUIET. The same device behaviour in fewer
#: round trips (docs/harness-protocol.md, "Batches").
FEATURES = ("batch",)
BATCH = "batch"
#: Most characters one ``chars`` message carries (its line stays under 256 characters).
BATCH_MAX = 8
#: The frame durations a version-2 ``tx`` may name (us): 10 bits at 800 to 1800 baud, far
#: outside any rate a receiver would frame, so a wrong unit is caught, a wrong rate judged.
FRAME_US_MIN, FRAME_US_MAX = 5556, 12500
#: Longest reply line accepted (a harness that writes more is flooding or writing garbage).
MAX_LINE = 200
#: Largest time accepted (about 11.6 days of bus time): beyond it a harness is counting wrong.
MAX_TIME_US = 10**12


class HarnessProtocolError(ValueError):
    """A reply that breaks the protocol; ``line`` is the offending text (escaped by callers)."""

    def __init__(self, reason: str, line: str) -> None:
        super().__init__(f"{reason}: {line!r}")
        self.reason = reason
        self.line = line


class Role(StrEnum):
    SENSOR = "sensor"
    RECORDER = "recorder"


class PlanKind(StrEnum):
    TX = "tx"  # transmit one character at ``start``
    #: hold a break from ``start`` to ``end``: a recorder's, or a sensor holding the line
    #: spacing for a break's length (some firmware "wakes" the line before every reply)
    BRK = "brk"
    WAIT = "wait"  # nothing before ``start``; tell me when it comes
    IDLE = "idle"  # nothing until something happens on the line
    DONE = "done"  # the job is finished (recorder harnesses only)
    #: ``cannot [WORDS]``: this recorder cannot do the job (recorder harnesses only)
    CANNOT = "cannot"


@dataclass(frozen=True, slots=True)
class Plan:
    """What the harness will do next if nothing happens on the line first."""

    kind: PlanKind
    start: int = 0  # us; TX/BRK: when it starts, WAIT: when to wake the harness
    end: int = 0  # us; BRK only
    wire: int = 0  # TX only: the 8 wire bits
    duration: int = 0  # TX only, version 2: the frame's own length in us (0: one 1200-baud frame)
    reason: str = ""  # CANNOT only: the harness's own words, if any


def us(seconds: float) -> int:
    """A bus time in seconds as the protocol's whole microseconds."""
    return round(seconds * 1e6)


def seconds(micro: int) -> float:
    return micro / 1e6


# the tool's messages (one line each, newline added by the channel)
def hello(role: Role) -> str:
    return f"hello {VERSION} {role}"


def job(now: float, task: str, commands: tuple[str, ...]) -> str:
    return " ".join(("job", str(us(now)), task, *commands))


def line_break(start: float, end: float) -> str:
    return f"break {us(start)} {us(end)}"


def heard(wire: int, start: float, end: float) -> str:
    return f"char {us(start)} {us(end)} {wire:02x}"


def sent(wire: int, start: float, end: float) -> str:
    return f"sent {us(start)} {us(end)} {wire:02x}"


def time_is(now: float) -> str:
    return f"time {us(now)}"


def quiet_until(limit: float) -> int | None:
    """The QUIET field for a bus time ``limit`` (s) before which the tool starts nothing: the
    whole microseconds Q such that every ``wait T`` with T < Q is before ``limit`` (floor,
    so a harness never wakes itself where the tool would not have); None when unbounded."""
    if not limit < MAX_TIME_US / 1e6:
        return None
    return int(limit * 1e6)


def with_quiet(message: str, limit: float | None, now: float) -> str:
    """A line event's ``message`` for a batch harness: with its QUIET field when the tool
    starts nothing before ``limit`` (s) and that is after ``now`` (the harness may wake
    itself for any ``wait`` before it); unchanged when nothing is promised."""
    quiet = None if limit is None else quiet_until(limit)
    return message if quiet is None or quiet <= us(now) else f"{message} {quiet}"


def heard_chars(frames: list[tuple[int, float, float]]) -> str:
    """``chars S1 E1 XX1 S2 E2 XX2 ...``: the tool's characters ``(wire, start, end)`` of one
    write, back to back, each sent only if the harness has not transmitted before its START."""
    return "chars " + " ".join(f"{us(s)} {us(e)} {w:02x}" for w, s, e in frames)


BYE = "bye"


def check_line(raw: bytes) -> str:
    """The reply as text, or an error if it is too long, not ASCII or holds control bytes."""
    text = raw.decode("ascii", errors="replace").rstrip("\r")
    if len(raw) > MAX_LINE:
        raise HarnessProtocolError(f"reply longer than {MAX_LINE} characters", text[:MAX_LINE])
    if any(not (32 <= b < 127) for b in raw.rstrip(b"\r")):
        raise HarnessProtocolError("reply holds bytes that are not printable ASCII", text)
    return text


def parse_hello(text: str) -> str:
    """The harness's name from its ``hello 1 [name]`` (or ``hello 2 [name]``) answer."""
    return parse_hello_version(text)[0]


def parse_hello_version(text: str) -> tuple[str, int]:
    """The harness's name and the protocol version it answered with (one of ``VERSIONS``)."""
    name, version, _ = parse_hello_features(text)
    return name, version


def parse_hello_features(text: str) -> tuple[str, int, frozenset[str]]:
    """The harness's name, version and the features it added (``hello 2+batch NAME``: each
    one of ``FEATURES``, at most once)."""
    parts = text.split(maxsplit=2)
    if not parts or parts[0] != "hello":
        raise HarnessProtocolError("expected 'hello 1 [name]' as the first reply", text)
    version, *features = parts[1].split("+") if len(parts) > 1 else ("",)
    if version not in {str(v) for v in VERSIONS}:
        raise HarnessProtocolError(f"harness speaks another protocol version, not {VERSION}", text)
    unknown = [f for f in features if f not in FEATURES]
    if unknown or len(set(features)) != len(features):
        raise HarnessProtocolError(
            f"unknown or repeated feature {'+'.join(unknown or features)!r} "
            f"(known: {', '.join(FEATURES)})",
            text,
        )
    return (parts[2] if len(parts) > 2 else ""), int(version), frozenset(features)


#: The answer to ``chars``: ``heard K PLAN`` (K the characters heard, PLAN the plan after them).
HEARD = "heard"


def parse_heard(text: str, count: int) -> tuple[int, str]:
    """How many of a ``chars`` message's ``count`` characters the harness heard (1..count),
    and the text of its plan after them (checked by :func:`parse_plan`)."""
    parts = text.split(" ", 2)
    if len(parts) < 3 or parts[0] != HEARD:
        raise HarnessProtocolError("a 'chars' message is answered 'heard K PLAN'", text)
    if not parts[1].isdigit() or not 1 <= int(parts[1]) <= count:
        raise HarnessProtocolError(f"'heard' takes a count from 1 to {count}", text)
    return int(parts[1]), parts[2]


def _time(field: str, text: str, *, bounded: bool = True) -> int:
    """A time field (us). ``bounded``: beyond :data:`MAX_TIME_US` is a harness counting
    wrong; a ``wait`` is not bounded (see :func:`parse_plan`)."""
    if not field.isdigit():
        raise HarnessProtocolError(f"time {field!r} is not a whole number of microseconds", text)
    value = int(field)
    if bounded and value > MAX_TIME_US:
        raise HarnessProtocolError("time beyond 10^12 us (units wrong?)", text)
    return value


def _byte(field: str, text: str) -> int:
    if len(field) != 2 or any(c not in "0123456789abcdefABCDEF" for c in field):
        raise HarnessProtocolError(f"byte {field!r} is not two hex digits", text)
    return int(field, 16)


_FIELDS = {"tx": 3, "brk": 3, "wait": 2, "idle": 1, "done": 1}
#: Longest reason a ``cannot`` keeps (the harness's words are untrusted and unbounded).
MAX_REASON = 200

#: A recorder harness's report of values its logger logged: ``log CMD VALUE...`` lines,
#: written before any plan (they answer nothing; several for one command append).
LOG = "log"
#: Most ``log`` lines one job may write (99 concurrent or 120 HA values take a few lines).
MAX_LOG_LINES = 1000


@dataclass(frozen=True, slots=True)
class LogLine:
    """Values the logger logged for the measurement ``command`` (wire text, ``0M!``)."""

    command: str
    values: tuple[str, ...]


def is_log(text: str) -> bool:
    return text.split(" ", 1)[0] == LOG


def parse_log(text: str) -> LogLine:
    """``log CMD VALUE...``: CMD is the measurement command as sent, with its address and
    ``!`` (the values are the logger's own text, judged against the wire, not here)."""
    parts = text.split(" ")
    if len(parts) < 2 or not parts[1]:
        raise HarnessProtocolError("'log' takes a command and the values logged for it", text)
    command = parts[1]
    if len(command) < 2 or not command.endswith("!") or "!" in command[:-1]:
        raise HarnessProtocolError(f"log command {command!r} is not wire text like 0M!", text)
    if "" in parts[2:]:
        raise HarnessProtocolError("log values are separated by one space", text)
    return LogLine(command, tuple(parts[2:]))


#: How far before now a ``brk`` may start and still be taken as starting now: frame
#: times are whole microseconds rounded from 8333.33 us frames, so a harness that adds frame
#: lengths itself lands up to a microsecond or two off the tool's rounded figure.
PAST_SLACK_US = 2


def _past(word: str, start: int, now: int) -> str:
    return (
        f"'{word}' starts at {start} us, {now - start} us before now ({now} us): the tool "
        "cannot send in the past (plan from the time of the message you answer)"
    )


def parse_plan(
    text: str,
    role: Role,
    now: int,
    since: int | None = None,
    version: int = VERSION,
    previous: Plan | None = None,
) -> Plan:
    """Check one plan reply against the role and the time ``now`` (us) of the message it
    answers. A ``brk`` must not start before ``now``: the tool cannot send in the past, and
    starting it "now" instead would shorten the break behind the harness's back, so that the
    recorder is judged for the harness's mistake (a stale clock, as a program let run ahead
    of the tool's time has). A ``tx`` start before ``now`` still means "as soon as the line
    lets me". The one past break start that is no mistake: a ``char``/``break`` message is
    told after the frame ends, so a plan made before it for a time inside that frame is held
    back by it, and repeating it is right; ``since`` (the reported frame's START) is then
    the earliest start accepted. A ``wait`` must be later than ``now`` (else the harness
    would be woken forever without time passing), and may be any later time: it only promises
    nothing before T, so a firmware's long sleep (a uint32_t of milliseconds read from a reply
    that never came: 49.7 days) is what it says, ended by the job's budget or the next event,
    not a harness counting wrong as a ``tx``/``brk`` that far out is. A version-2 harness may
    add a ``tx``'s duration and is held to the clock for ``tx`` as for ``brk``
    (:func:`_parse_tx`). A sensor harness may plan a ``brk`` too (an extension: it used to
    be an ERROR, so no harness that worked sends it): firmware that holds the line spacing
    for a break's length before its reply (the 2013 Arduino-SDI-12 library's
    ``wakeSensors()`` in a sensor sketch) is put on the line as it does it, not stopped."""
    floor = now if since is None else min(now, since)
    parts = text.split(" ")
    if parts[0] == PlanKind.TX and version >= 2:
        return _parse_tx(parts, text, now, since, previous)
    word = parts[0]
    if word == PlanKind.CANNOT:
        if role is Role.SENSOR:
            raise HarnessProtocolError(f"'{word}' is for recorder harnesses only", text)
        return Plan(PlanKind.CANNOT, reason=text[len(word) :].strip()[:MAX_REASON])
    if word not in _FIELDS:
        raise HarnessProtocolError("unknown reply (want tx, wait, idle, brk, done or cannot)", text)
    if len(parts) != _FIELDS[word]:
        raise HarnessProtocolError(f"'{word}' takes {_FIELDS[word] - 1} field(s)", text)
    kind = PlanKind(word)
    if role is Role.SENSOR and kind is PlanKind.DONE:
        raise HarnessProtocolError(f"'{word}' is for recorder harnesses only", text)
    if kind is PlanKind.TX:
        # a character planned in the past goes out as soon as the line lets it (harnesses
        # that queue replies rely on it, e.g. a service request queued behind a reply)
        return Plan(kind, start=_time(parts[1], text), wire=_byte(parts[2], text))
    if kind is PlanKind.BRK:
        start, end = _time(parts[1], text), _time(parts[2], text)
        if start < floor - PAST_SLACK_US:
            raise HarnessProtocolError(_past(word, start, now), text)
        if end <= max(start, now):
            raise HarnessProtocolError("break ends before it starts (or before now)", text)
        return Plan(kind, start=start, end=end)
    if kind is PlanKind.WAIT:
        start = _time(parts[1], text, bounded=False)
        if start <= now:
            raise HarnessProtocolError(f"wait time is not after now ({now} us)", text)
        return Plan(kind, start=start)
    return Plan(kind)


def _parse_tx(
    parts: list[str], text: str, now: int, since: int | None, previous: Plan | None
) -> Plan:
    """A version-2 ``tx START XX [DURATION]``. Its START must not be before now (within the
    rounding slack): a harness that plans a character in the past has let its device run
    ahead of the tool's clock or answered a stale message, and the tool starting it "now"
    instead would move the device's timing behind its back. The one exception is the plan
    it had, repeated unchanged after a ``char``/``break`` reported a frame that began before
    it (START at or after that frame's START): it goes out once the line is free. A *new*
    plan inside the frame just reported transmits before the line is idle: an error too.
    DURATION, when given, is the frame's own length."""
    if len(parts) not in (3, 4):
        raise HarnessProtocolError("'tx' takes 2 or 3 field(s) (version 2)", text)
    start, wire = _time(parts[1], text), _byte(parts[2], text)
    repeated = previous is not None and previous.kind is PlanKind.TX
    repeated = repeated and (previous.start, previous.wire) == (start, wire)  # type: ignore[union-attr]
    if start < now - PAST_SLACK_US and not (repeated and since is not None and start >= since):
        if since is not None and start >= since - PAST_SLACK_US:
            raise HarnessProtocolError(
                f"'tx' starts at {start} us, inside the character or break just reported "
                f"({since}..{now} us): a new plan must wait for the line to be idle",
                text,
            )
        raise HarnessProtocolError(_past("tx", start, now), text)
    duration = _time(parts[3], text) if len(parts) == 4 else 0
    if len(parts) == 4 and not FRAME_US_MIN <= duration <= FRAME_US_MAX:
        raise HarnessProtocolError(
            f"frame duration {duration} us is outside {FRAME_US_MIN}..{FRAME_US_MAX} us "
            "(10 bits at 800 to 1800 baud)",
            text,
        )
    return Plan(PlanKind.TX, start=max(start, now), wire=wire, duration=duration)
