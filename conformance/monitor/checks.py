"""Rules a single line on the bus breaks, checked as it is heard (sans-I/O).

The monitor judges the whole recording when it stops (``judge`` on its transcript); while it
runs, it points at what is visibly wrong line by line, so a person watching a field bus sees
a problem when it happens. These checks are cheap and local: the reply's format for the command
it answers (the protocol parsers of :mod:`conformance.protocol.responses`, which name the
requirement each violation breaks), parity, and when the reply started after the command
(R-7.0-09/10, judged with the stamps' uncertainty by
:func:`~conformance.judges.timing.judge_window`: only a start the stamps' uncertainty cannot
excuse is flagged). They are hints beside the live view, not verdicts.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..judges.timing import judge_window
from ..protocol.commands import (
    MEASUREMENT_KINDS,
    Command,
    Kind,
    command_or_none,
)
from ..protocol.framing import STX
from ..protocol.responses import (
    check_address,
    is_service_request,
    parse_data_reply_for,
    parse_ident,
    parse_measurement_reply_for,
    split_line,
)
from ..protocol.timing import CHAR_TIME, RESPONSE_START_MAX, TOLERANCE
from ..transcript import Event
from ..verdicts import Verdict
from ..view.sides import expected_reply_address


@dataclass(frozen=True)
class Flag:
    """A rule one line breaks; ``sure`` False: a SHOULD rule or a lenient decision (the
    parsers mark those as warnings), shown as such."""

    requirement: str
    message: str
    sure: bool = True

    def __str__(self) -> str:
        mark = "" if self.sure else "(warn) "
        return f"{mark}{self.requirement}: {self.message}"


@dataclass
class Context:
    """What earlier lines tell about the next: the command being answered, and the last
    measurement per address (a ``D`` reply's format depends on it)."""

    command_text: str = ""
    command_end: float | None = None  # its last stop bit; None once a reply began
    command_last: Event | None = None
    answered: bool = False
    measurements: dict[str, Command] | None = None

    def __post_init__(self) -> None:
        if self.measurements is None:
            self.measurements = {}


def parity_flags(events: list[Event]) -> list[Flag]:
    bad = [k for k, e in enumerate(events) if not e.parity_ok]
    if not bad:
        return []
    where = ", ".join(str(k + 1) for k in bad[:5])
    return [Flag("R-4.1-02", f"parity error in character {where} (7E1 wants even parity)")]


def command_flags(text: str, ctx: Context, events: list[Event]) -> list[Flag]:
    """A recorder's transmission: note it as the command being answered."""
    ctx.command_text, ctx.answered = text, False
    ctx.command_end, ctx.command_last = events[-1].end, events[-1]
    flags = parity_flags(events)
    command = command_or_none(text)
    if command is not None and command.kind in MEASUREMENT_KINDS:
        assert ctx.measurements is not None
        ctx.measurements[text[0]] = command
    return flags


def reply_flags(
    text: str, ctx: Context, events: list[Event], run_uncertainty: float = 0.0
) -> list[Flag]:
    """A sensor's line: its timing after the command and its format for that command.
    ``run_uncertainty`` (s): what the run measures its stamps to be worth, beside the
    figure the stamps carry (the final judging uses the larger: so does the flag)."""
    flags = parity_flags(events)
    if ctx.command_end is not None and not ctx.answered and ctx.command_last is not None:
        flags += _timing_flags(ctx.command_last, events[0], run_uncertainty)
    first_line = not ctx.answered
    ctx.answered = True
    if not first_line or not ctx.command_text or len(text) > 1 and text[1] == chr(STX):
        return flags  # a later line (multi-line text, a service request): framing only
    command = command_or_none(ctx.command_text)
    if command is None:
        return flags
    if command.kind is Kind.BINARY_DATA:
        return flags  # an 8N1 packet: judged on Ctrl-C, not here
    if command.kind in (Kind.MEASURE, Kind.VERIFY) and is_service_request(
        text.rstrip("\r\n"), ctx.command_text[0]
    ):
        return flags
    return flags + _format_flags(text, command, ctx)


def unsolicited_flags(text: str, events: list[Event]) -> list[Flag]:
    """A sensor's line with no command before it (a service request): its framing."""
    _body, framing = split_line(text)
    return parity_flags(events) + [Flag(v.requirement, v.message) for v in framing]


def _timing_flags(command_last: Event, first: Event, run_uncertainty: float = 0.0) -> list[Flag]:
    """R-7.0-09/10 where the stamps decide it: a start that may be within the window given
    their uncertainty, or the run's measured one, is no flag (the judging at the end weighs
    it with the whole run)."""
    delay = first.start - command_last.end
    u = max(command_last.uncertainty, first.uncertainty, run_uncertainty)
    flags: list[Flag] = []
    for req, low, high, says in (
        ("R-7.0-09", CHAR_TIME, None, "earlier than 7.93 ms"),
        ("R-7.0-10", None, RESPONSE_START_MAX, "later than 15.40 ms"),
    ):
        finding = judge_window(
            req,
            "reply start",
            delay,
            u,
            low=low,
            high=high,
            tolerance=TOLERANCE,
            evidence=[f"reply start at t={first.start:.4f} s"],
        )
        if finding.verdict is Verdict.FAIL:
            flags.append(
                Flag(
                    req,
                    f"reply started {delay * 1e3:.2f} ms (\u00b1{u * 1e3:.2f}) after the "
                    f"command: {says}",
                )
            )
    return flags


def _format_flags(text: str, command: Command, ctx: Context) -> list[Flag]:
    """The reply's format for ``command``, by the protocol parsers."""
    expected = expected_reply_address(ctx.command_text)
    crc = _crc_due(command, ctx)
    body, framing = split_line(text, crc_positions=3 if crc else 0)
    found = list(framing)
    try:
        if command.kind is Kind.IDENTIFY:
            found += parse_ident(body, expected).violations
        elif command.kind in MEASUREMENT_KINDS:
            reply = parse_measurement_reply_for(body, command, expected_address=expected)
            found += reply.violations
        elif command.kind in (Kind.DATA, Kind.CONTINUOUS):
            target = command
            if command.kind is Kind.DATA:
                assert ctx.measurements is not None
                target = ctx.measurements.get(command.address, command)
            if target.kind is Kind.DATA:  # no measurement heard before: address only
                found += check_address(body, expected)
            else:
                found += parse_data_reply_for(body, target, expected_address=expected).violations
        else:
            found += check_address(body, expected)
    except ValueError:  # a command the parsers do not describe: its address at least
        found += check_address(body, expected)
    seen: set[tuple[str, str]] = set()
    flags: list[Flag] = []
    for v in found:
        if (v.requirement, v.message) not in seen:
            seen.add((v.requirement, v.message))
            flags.append(Flag(v.requirement, v.message, sure=not v.warning))
    return flags


def _crc_due(command: Command, ctx: Context) -> bool:
    target = command
    if command.kind is Kind.DATA:
        assert ctx.measurements is not None
        target = ctx.measurements.get(command.address, command)
    return bool(getattr(target, "returns_crc", False))
