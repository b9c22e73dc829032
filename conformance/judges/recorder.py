"""Judges of a data recorder, from the wire alone (pure functions over transcript events).

In the recorder role the tool plays the sensors and watches what the recorder under test
does. The events are first read into a role-neutral view (:func:`read_line`): each
transmission of the recorder (:class:`Sent`: the break before it, its characters, and what the
sensors sent afterwards until the recorder acted again). ``is_recorder`` says which events are
the recorder's: origin ``tool`` on the simulated bus, where the recorder runs on the tool's
link; the sensors' side on a real port. Timing is measured from the sensor side with the
link's uncertainty, and judged with :func:`~conformance.judges.timing.judge_window`.

Each judge takes the line of one scenario (or of several) and returns findings for the
requirements it owns; nothing here talks to a link.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

from ..protocol.binary import packet_length, parse_binary_packet
from ..protocol.commands import (
    ADDRESS_CHARS,
    SERVICE_REQUEST_KINDS,
    Command,
    CommandError,
    Kind,
    parse_command,
)
from ..protocol.responses import parse_data_reply, parse_measurement_reply_for, split_line
from ..protocol.timing import (
    BREAK_MIN,
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    MARKING_AFTER_BREAK,
    MULTILINE_GAP_MAX,
    NO_BREAK_WINDOW,
    RETRY_AFTER_BREAK,
    RETRY_MAX,
    RETRY_MIN,
    TOLERANCE,
)
from ..transcript import TOOL, Event, EventKind, decode_7e1, decode_8n1, escape, text_end
from ..verdicts import Finding, Verdict
from .reply_validity import (
    ETX,
    NO_LIMIT,
    NO_REPLY,
    STX,
    Reason,
    ReplyProblem,
    check_packet,
    check_reply,
)
from .tally import Tally
from .timing import combine as combine_timing
from .timing import judge_window

IsRecorder = Callable[[Event], bool]

#: Marking after a ``!`` that starts a new command; anything sooner (``0M!!``) is still part
#: of the one before, so a ``!`` in the middle of a command is seen (R-4.4-04).
_NEW_COMMAND = MARKING_AFTER_BREAK - TOLERANCE

#: A recorder reacts to a service request (or to ttt running out) with aD0! within this long.
#: The standard says "when it arrives"; the tool allows half a second for a logger's own work
#: and fails only a recorder that visibly waits for something else (a tool decision).
REACTION = 0.5
#: Values a recorder must be able to store from one concurrent measurement (R-4.4.7-07, 2000).
MIN_CONCURRENT_STORE = 20
_DATA = re.compile(r"^(.)D(B?)([0-9]+)!$")
_SR_KINDS = SERVICE_REQUEST_KINDS
_CONCURRENT = (Kind.CONCURRENT, Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY)


def recorder_is_tool(event: Event) -> bool:
    """The recorder's events on the simulated bus (it runs on the tool's link)."""
    return event.origin == TOOL


# -- the view -----------------------------------------------------------------------------------
@dataclass
class Sent:
    """One transmission of the recorder and what the sensors sent until it acted again."""

    break_event: Event | None
    chars: list[Event]
    heard: list[Event] = field(default_factory=list)
    part: int = 0  # which scenario of a merged line it belongs to

    @property
    def text(self) -> str:
        return decode_7e1(self.chars)

    @property
    def address(self) -> str:
        return self.text[:1]

    @property
    def start(self) -> float:
        """Where the recorder took the line: the break if there was one."""
        return (self.break_event or self.chars[0]).start

    @property
    def first_char(self) -> float:
        return self.chars[0].start

    @property
    def end(self) -> float:
        return self.chars[-1].end

    @property
    def command(self) -> Command | None:
        try:
            return parse_command(self.text)
        except CommandError:
            return None

    @property
    def data_index(self) -> tuple[bool, int, str] | None:
        """``(binary, index, digits)`` of an ``aDn!``/``aDBn!``, leading zeros included."""
        m = _DATA.match(self.text)
        return (m[2] == "B", int(m[3]), m[3]) if m else None

    @property
    def binary(self) -> bool:
        d = self.data_index
        return d is not None and d[0]

    @property
    def answer(self) -> list[Event]:
        """The reply proper: up to the first LF (7E1), the packet length (DB), or ETX (text)."""
        heard = [e for e in self.heard if e.start >= self.end]
        if self.binary:
            length = packet_length(decode_8n1(heard))
            return heard[:length] if length is not None else heard
        text = len(heard) > 1 and heard[1].char7 == STX
        for i, e in enumerate(heard):
            if text and e.char7 == ETX:
                return heard[: i + 1]
            if not text and e.char7 == 0x0A:
                return heard[: i + 1]
            if text and e.char7 == 0x0A:
                nxt = heard[i + 1] if i + 1 < len(heard) else None
                if nxt is None or nxt.start - e.end > MULTILINE_GAP_MAX + TOLERANCE:
                    return heard[: i + 1]
        return heard

    @property
    def after(self) -> list[Event]:
        """What the sensors sent after the reply (service requests, chatter)."""
        answer = self.answer
        return [e for e in self.heard if e.start >= self.end and e not in answer]


@dataclass
class Line:
    """A scenario's wire, as the recorder used it."""

    sent: list[Sent]
    breaks: list[Event]
    chars: list[Event]  # every character, both sides, in time order


def read_line(
    events: Iterable[Event], is_recorder: IsRecorder = recorder_is_tool, part: int = 0
) -> Line:
    """The recorder's transmissions among ``events`` (one scenario: ``part`` numbers it)."""
    sent: list[Sent] = []
    breaks: list[Event] = []
    chars: list[Event] = []
    pending: Event | None = None
    current: Sent | None = None
    for e in sorted((e for e in events if e.kind is not EventKind.NOTE), key=lambda e: e.start):
        if e.kind is EventKind.CHAR:
            chars.append(e)
        if is_recorder(e):
            if e.kind is EventKind.BREAK:
                breaks.append(e)
                pending, current = e, None
            elif current is None or (
                current.text.endswith("!") and e.start - current.end >= _NEW_COMMAND
            ):
                current = Sent(pending, [e], part=part)
                sent.append(current)
                pending = None
            else:
                current.chars.append(e)
        elif e.kind is EventKind.CHAR and current is not None:
            current.heard.append(e)
    return Line(sent, breaks, chars)


def merge_lines(lines: Sequence[Line]) -> Line:
    """Several scenarios judged together; retries and measurements never span two of them."""
    return Line(
        [s for line in lines for s in line.sent],
        [b for line in lines for b in line.breaks],
        [c for line in lines for c in line.chars],
    )


def _previous_activity(line: Line, sent: Sent) -> float | None:
    """End of the last event on the line before ``sent`` took it (either side)."""
    t = sent.start
    ends = [e.end for e in line.chars if e.end <= t] + [b.end for b in line.breaks if b.end <= t]
    return max(ends) if ends else None


def combine(rid: str, findings: list[Finding], what: str) -> Finding:
    """Recorder limits are mostly minimums (break length, marking, waits): the smallest
    measurement is the one to show."""
    return combine_timing(rid, findings, what, smallest_is_worst=True)


def _at(sent: Sent) -> str:
    return f"{escape(sent.text)} at t={sent.first_char:.3f} s"


# -- reply validity (the recorder's view of section 7.2) -------------------------------------
def reply_problem(sent: Sent, crc_expected: bool | None, uncertainty: float) -> ReplyProblem | None:
    """Why the sensor's reply to ``sent`` was not a valid reply (:data:`NO_REPLY` if none
    came), by the judges' own rules (:mod:`.reply_validity`), not the golden recorder's."""
    if sent.binary:
        return check_packet(sent.answer, address=sent.address, command_end=sent.end)
    return check_reply(
        sent.command,
        sent.answer,
        address=sent.address,
        command_end=sent.end,
        gap_limit=CHAR_TIME + TOLERANCE + uncertainty,
        crc_expected=crc_expected,
    )


def crc_context(line: Line) -> dict[int, bool | None]:
    """For each transmission index: whether its reply carries a CRC (D after MC, CC, HA...)."""
    pending: dict[str, bool] = {}
    result: dict[int, bool | None] = {}
    for i, s in enumerate(line.sent):
        cmd = s.command
        if cmd is not None and cmd.starts_measurement:
            pending[cmd.address] = cmd.returns_crc
        result[i] = pending.get(s.address) if s.data_index is not None else None
    return result


@dataclass
class Attempt:
    sent: Sent
    problem: ReplyProblem | None  # None: valid reply

    @property
    def retry(self) -> bool:
        return self.sent.break_event is None


@dataclass
class Tries:
    """Consecutive transmissions of one command text: the first try and its retries."""

    text: str
    attempts: list[Attempt]

    def sequences(self) -> list[list[Attempt]]:
        """Split at breaks: each break + command + retries is one sequence (R-7.2-04)."""
        out: list[list[Attempt]] = []
        for a in self.attempts:
            if not out or a.sent.break_event is not None:
                out.append([a])
            else:
                out[-1].append(a)
        return out

    @property
    def succeeded(self) -> bool:
        return any(a.problem is None for a in self.attempts)


def tries(line: Line, uncertainty: float) -> list[Tries]:
    crc = crc_context(line)
    out: list[Tries] = []
    for i, s in enumerate(line.sent):
        if not s.text.endswith("!"):
            continue  # no command, so no reply to retry for; R-4.4-04 judges its text
        attempt = Attempt(s, reply_problem(s, crc[i], uncertainty))
        last = out[-1].attempts[-1] if out else None
        if (
            last is not None
            and last.sent.part == s.part
            and last.sent.text == s.text
            and (last.problem is not None)
        ):
            out[-1].attempts.append(attempt)
        else:
            out.append(Tries(s.text, [attempt]))
    return out


# -- measurements ---------------------------------------------------------------------------------
@dataclass
class Taken:
    """A measurement the recorder started and what it did until it was done with it."""

    index: int  # position of the starting transmission in line.sent
    start: Sent
    command: Command
    ttt: int
    count: int
    reply_end: float
    service_request_end: float | None
    data: list[tuple[Sent, ReplyProblem | None]]  # data transmissions, with their problems
    next_start: Sent | None  # the next measurement command to the same sensor, if any
    others: list[Sent]  # transmissions to other sensors before the data were all in

    @property
    def kind(self) -> Kind:
        return self.command.kind

    def values(self) -> list[str]:
        """Values of the valid data replies, each index counted once."""
        seen: set[int] = set()
        values: list[str] = []
        for sent, problem in self.data:
            d = sent.data_index
            if problem is not None or d is None or d[1] in seen:
                continue
            seen.add(d[1])
            if d[0]:
                packet = parse_binary_packet(decode_8n1(sent.answer))
                values += [repr(v) for v in packet.values]
            else:
                values += data_values(sent, self.command)
        return values

    @property
    def first_data(self) -> Sent | None:
        return self.data[0][0] if self.data else None


def data_values(sent: Sent, measurement: Command) -> list[str]:
    """The values of a valid D reply to ``sent`` after ``measurement`` (its CRC taken off)."""
    body, _ = split_line(decode_7e1(sent.answer))
    return parse_data_reply(body, crc_expected=measurement.returns_crc, limit=NO_LIMIT).values


def _service_request_end(events: list[Event], address: str) -> float | None:
    """End of the first ``a<CR><LF>`` with good parity among ``events`` (R-4.4.6-01)."""
    return text_end(events, f"{address}\r\n")


def measurements(line: Line, uncertainty: float) -> list[Taken]:
    """Every measurement the recorder started with a valid ``atttn``-type reply."""
    crc = crc_context(line)
    problems = [reply_problem(s, crc[i], uncertainty) for i, s in enumerate(line.sent)]
    taken: list[Taken] = []
    for i, s in enumerate(line.sent):
        cmd = s.command
        if cmd is None or not cmd.starts_measurement or problems[i] is not None:
            continue
        body, _ = split_line(decode_7e1(s.answer))
        parsed = parse_measurement_reply_for(body, cmd)
        if parsed.ttt is None or parsed.count is None:
            continue
        ttt, count = parsed.ttt, parsed.count
        sr = _service_request_end(s.after, cmd.address)
        data: list[tuple[Sent, ReplyProblem | None]] = []
        others: list[Sent] = []
        nxt: Sent | None = None
        for j in range(i + 1, len(line.sent)):
            t = line.sent[j]
            if t.part != s.part:
                break
            if t.address != cmd.address:
                others.append(t)
                continue
            tc = t.command
            if t.data_index is not None:
                data.append((t, problems[j]))
                continue
            if tc is not None and tc.starts_measurement:
                nxt = t
            break
        if data:
            last = data[-1][0]
            others = [o for o in others if o.start < last.end]
        taken.append(Taken(i, s, cmd, ttt, count, s.answer[-1].end, sr, data, nxt, others))
    return taken


# -- judges: breaks and command characters --------------------------------------------------------
def judge_breaks(line: Line, uncertainty: float) -> list[Finding]:
    """R-7.0-02: every break lasts at least 12 ms. R-7.0-06: after a break the recorder marks
    at least 8.33 ms before the first start bit of its command (both ±0.40 ms)."""
    lengths = [
        judge_window(
            "R-7.0-02",
            "break length",
            b.duration,
            uncertainty,
            low=BREAK_MIN,
            evidence=[f"break at t={b.start:.3f} s"],
        )
        for b in line.breaks
    ]
    markings = [
        judge_window(
            "R-7.0-06",
            "marking after the break",
            s.first_char - s.break_event.end,
            uncertainty,
            low=MARKING_AFTER_BREAK,
            evidence=[f"before {_at(s)}"],
        )
        for s in line.sent
        if s.break_event is not None
    ]
    return [combine("R-7.0-02", lengths, "break"), combine("R-7.0-06", markings, "marking")]


def judge_command_text(line: Line) -> list[Finding]:
    """R-4.2-01 printable command characters; R-4.4-04 ``!`` last and nowhere else; R-4.3-01
    the first character is the address (``?`` only in ``?!``)."""
    tally = Tally(("R-4.2-01", "R-4.4-04", "R-4.3-01"))
    for s in line.sent:
        text, where = s.text, escape(s.text)
        bad = [c for c in text if not 0x20 <= ord(c) <= 0x7E]
        tally.observe(where, ids=["R-4.2-01", "R-4.4-04", "R-4.3-01"])
        if bad:
            tally.fail("R-4.2-01", where, f"non-printable {escape(''.join(bad))} in the command")
        if not text.endswith("!") or "!" in text[:-1]:
            tally.fail("R-4.4-04", where, "'!' is not exactly the last character")
        first = text[:1]
        if not (first in ADDRESS_CHARS or text == "?!"):
            tally.fail("R-4.3-01", where, f"starts with {escape(first)}, not an address")
    return tally.findings("well formed")


def judge_character_gaps(line: Line, uncertainty: float) -> list[Finding]:
    """R-7.0-13: at most 1.66 ms of marking between the characters of a command (no
    tolerance); R-7.0-01: no gap leans on the ±0.40 ms that this limit does not have."""
    gaps = [
        (b.start - a.end, s) for s in line.sent for a, b in zip(s.chars, s.chars[1:], strict=False)
    ]
    found = [
        judge_window(
            "R-7.0-13",
            "marking between command characters",
            gap,
            uncertainty,
            high=INTER_CHAR_GAP_MAX,
            tolerance=0.0,
            evidence=[f"in {_at(s)}"],
        )
        for gap, s in gaps
    ]
    leaning = [
        (gap, s) for gap, s in gaps if INTER_CHAR_GAP_MAX < gap <= INTER_CHAR_GAP_MAX + TOLERANCE
    ]
    if leaning:
        gap, s = leaning[0]
        tol = Finding(
            "R-7.0-01",
            Verdict.FAIL,
            f"a {gap * 1e3:.2f} ms gap in {_at(s)} relies on the ±0.40 ms tolerance, which the "
            f"1.66 ms character gap does not have ({len(leaning)} such gap(s))",
            measured_ms=round(gap * 1e3, 3),
            limit_ms=1.66,
        )
    elif gaps:
        tol = Finding(
            "R-7.0-01",
            Verdict.PASS,
            f"{len(gaps)} command character gaps, none inside the tolerance band the 1.66 ms "
            "limit does not have; ±0.40 ms applied to every other recorder limit",
            observed=len(gaps),
        )
    else:
        tol = Finding("R-7.0-01", Verdict.INCONCLUSIVE, "no multi-character command observed")
    return [combine("R-7.0-13", found, "character gap"), tol]


def judge_bit_rate(line: Line, uncertainty: float) -> Finding:
    """R-4.1-01 (decision A14, ±2%): back-to-back command characters start one frame apart."""
    spacings = [
        (b.start - a.start, s)
        for s in line.sent
        for a, b in zip(s.chars, s.chars[1:], strict=False)
    ]
    if not spacings:
        return Finding("R-4.1-01", Verdict.INCONCLUSIVE, "no multi-character command observed")
    shortest, s = min(spacings, key=lambda x: x[0])
    finding = judge_window(
        "R-4.1-01",
        "shortest start-to-start spacing of command characters",
        shortest,
        2 * uncertainty,
        low=CHAR_TIME * 0.98,
        high=CHAR_TIME * 1.02,
        tolerance=0.0,
        evidence=[f"in {_at(s)}"],
        decision="A14",
    )
    too_slow = shortest - 2 * uncertainty > CHAR_TIME * 1.02
    if finding.verdict is Verdict.FAIL and too_slow:  # a gap, not a rate: see wire.judge_bit_rate
        finding.verdict = Verdict.INCONCLUSIVE
        finding.detail += " (no back-to-back characters: rate and gaps cannot be separated)"
    finding.detail += f"; about {10 / shortest:.0f} baud over {len(spacings)} spacings"
    return finding


# -- judges: when a break is due ------------------------------------------------------------------
def judge_break_rules(line: Line, uncertainty: float) -> list[Finding]:
    """R-7.0-17: a break before every command to a different sensor than the last one, or after
    more than 87 ms of marking. R-7.1-01: ``aD0!`` without a break only within 87 ms of the
    service request."""
    rule17: list[Finding] = []
    rule71: list[Finding] = []
    previous: Sent | None = None
    for s in line.sent:
        if previous is not None and previous.part != s.part:
            previous = None  # a new scenario: the line was idle and the sensors are new
        if s.break_event is None:
            where = [f"before {_at(s)}"]
            if previous is None or previous.address != s.address:
                who = "no earlier command" if previous is None else f"last was {previous.text}"
                rule17.append(
                    Finding(
                        "R-7.0-17",
                        Verdict.FAIL,
                        f"no break before {_at(s)}, a new sensor ({who})",
                        evidence=where,
                    )
                )
            else:
                quiet = s.first_char - (_previous_activity(line, s) or float("-inf"))
                rule17.append(
                    judge_window(
                        "R-7.0-17",
                        "marking before a command sent without a break",
                        quiet,
                        uncertainty,
                        high=NO_BREAK_WINDOW,
                        evidence=where,
                    )
                )
            if previous is not None and _follows_service_request(previous, s):
                sr_end = _service_request_end(previous.after, s.address)
                assert sr_end is not None
                rule71.append(
                    judge_window(
                        "R-7.1-01",
                        "aD0! without a break after the service request",
                        s.first_char - sr_end,
                        uncertainty,
                        high=NO_BREAK_WINDOW,
                        evidence=where,
                    )
                )
        elif previous is not None and _follows_service_request(previous, s):
            rule71.append(
                Finding(
                    "R-7.1-01",
                    Verdict.PASS,
                    f"a break before {_at(s)} after the service request",
                    observed=1,
                )
            )
        previous = s
    return [
        combine("R-7.0-17", rule17, "command without a break")
        if rule17
        else Finding("R-7.0-17", Verdict.PASS, _all_broke(line), observed=len(line.sent)),
        combine("R-7.1-01", rule71, "aD0! after a service request"),
    ]


def _all_broke(line: Line) -> str:
    return f"all {len(line.sent)} commands were sent after a break"


def _follows_service_request(previous: Sent, s: Sent) -> bool:
    cmd = previous.command
    d = s.data_index
    return (
        cmd is not None
        and cmd.kind in _SR_KINDS
        and d is not None
        and d[1] == 0
        and s.address == cmd.address
        and _service_request_end(previous.after, cmd.address) is not None
    )


# -- judges: waiting for data ---------------------------------------------------------------------
def judge_measure_waits(taken: Sequence[Taken], uncertainty: float) -> list[Finding]:
    """For aM!-type measurements with ttt > 0: R-4.4.5-04 no aD0! before the service request
    or ttt; R-4.4.5-07 the line left alone while waiting; R-4.4.5-05 aD0! promptly when the
    service request comes or ttt runs out (then after a break), and at once for ttt = 0
    (SHOULD); R-4.4.5-06 no traffic to other sensors until the data are in."""
    early: list[Finding] = []
    tally = Tally(("R-4.4.5-05", "R-4.4.5-06", "R-4.4.5-07"))
    for m in taken:
        if m.kind not in _SR_KINDS:
            continue
        where = escape(m.start.text)
        tally.observe(where, ids=["R-4.4.5-06"])
        for other in m.others:
            tally.fail(
                "R-4.4.5-06",
                where,
                f"{_at(other)} went to another sensor before the data of {where} were in",
            )
        first = m.first_data
        if m.ttt == 0:
            tally.observe(where, ids=["R-4.4.5-05"])
            if first is None or first.start - m.reply_end > REACTION:
                tally.fail(
                    "R-4.4.5-05",
                    where,
                    "ttt = 000 but aD0! did not follow at once",
                    warning=True,
                )
            continue
        ready = m.reply_end + m.ttt
        sr = m.service_request_end if m.service_request_end is not None else None
        waited_until = min(sr, ready) if sr is not None else ready
        moved = [s for s in m.others if s.start < waited_until] + (
            [first] if first is not None and first.start < waited_until else []
        )
        tally.observe(where, ids=["R-4.4.5-07"])
        if moved:
            tally.fail(
                "R-4.4.5-07",
                where,
                f"the recorder took the line {moved[0].start - m.reply_end:.3f} s after the "
                f"reply, while a service request could still come",
            )
        if first is None:
            tally.fail("R-4.4.5-05", where, "no aD0! after the measurement")
            continue
        if sr is None or sr > first.start:
            early.append(
                judge_window(
                    "R-4.4.5-04",
                    "aD0! (or its break) after the reply, with no service request before it",
                    first.start - m.reply_end,
                    uncertainty,
                    low=float(m.ttt),
                    evidence=[f"{_at(first)} after {where} announced ttt={m.ttt}"],
                )
            )
        else:
            early.append(
                Finding(
                    "R-4.4.5-04",
                    Verdict.PASS,
                    f"aD0! only after the service request ({where})",
                    observed=1,
                )
            )
        tally.observe(where, ids=["R-4.4.5-05"])
        trigger = sr if sr is not None and sr <= ready else ready
        delay = first.start - trigger
        if delay > REACTION:
            what = "the service request" if trigger == sr else "ttt"
            tally.fail(
                "R-4.4.5-05",
                where,
                f"aD0! came {delay:.3f} s after {what} (allowed {REACTION} s)",
            )
        if trigger != sr and first.break_event is None:
            tally.fail("R-4.4.5-05", where, "aD0! after ttt ran out, without a break first")
    return [combine("R-4.4.5-04", early, "wait for data"), *tally.findings()]


def judge_concurrent_waits(taken: Sequence[Taken], uncertainty: float) -> list[Finding]:
    """R-4.4.7-06: after a concurrent reply with ttt > 0, no data command to that sensor before
    ttt (talking to other sensors meanwhile is allowed)."""
    found = []
    for m in taken:
        if m.kind not in _CONCURRENT or not m.ttt or m.first_data is None:
            continue
        found.append(
            judge_window(
                "R-4.4.7-06",
                "first data command (or its break) after the concurrent reply",
                m.first_data.start - m.reply_end,
                uncertainty,
                low=float(m.ttt),
                evidence=[f"{_at(m.first_data)} after {escape(m.start.text)} (ttt={m.ttt})"],
            )
        )
    return [combine("R-4.4.7-06", found, "concurrent wait")]


# -- judges: collecting data ----------------------------------------------------------------------
def _collection_end(m: Taken) -> tuple[Sent | None, ReplyProblem | None, bool]:
    """The last data transmission, its problem, and whether its valid reply was empty."""
    if not m.data:
        return None, None, False
    sent, problem = m.data[-1]
    if problem is not None:
        return sent, problem, False
    if sent.binary:
        packet = parse_binary_packet(decode_8n1(sent.answer))
        return sent, None, not packet.values
    return sent, None, not data_values(sent, m.command)


def judge_data_collection(taken: Sequence[Taken]) -> list[Finding]:
    """R-4.4.8-05: aD0!, aD1!, ... in order until every announced value is in; after a valid
    empty reply the measurement is issued again. A collection that ended on a reply the
    recorder found invalid is left to the retry rules (section 7.2)."""
    tally = Tally(("R-4.4.8-05",))
    for m in taken:
        if m.kind is Kind.HIGH_VOLUME_BINARY or not m.count:
            continue
        where = escape(m.start.text)
        tally.observe(where)
        indices = [d[1] for s, _ in m.data if (d := s.data_index) is not None]
        order = [i for n, i in enumerate(indices) if n == 0 or indices[n - 1] != i]
        if order != list(range(len(order))):
            tally.fail("R-4.4.8-05", where, f"data indices went {order}, not 0, 1, 2, ...")
            continue
        have = len(m.values())
        if have >= m.count:
            continue
        last, problem, empty = _collection_end(m)
        if problem is not None:
            continue
        if empty:
            if m.next_start is None or m.next_start.text != m.start.text:
                tally.fail(
                    "R-4.4.8-05",
                    where,
                    f"{escape(last.text) if last else 'aD0!'} came back empty and the "
                    "measurement was not issued again",
                )
            continue
        stop = escape(last.text) if last is not None else "the reply"
        tally.fail("R-4.4.8-05", where, f"stopped after {stop} with {have} of {m.count} values")
    return tally.findings("every announced value collected in order")


def judge_concurrent_storage(taken: Sequence[Taken], asked: Sequence[str] = ()) -> list[Finding]:
    """R-4.4.7-07: a concurrent measurement of more than 20 values: at least 20 read and stored
    (the 2000 text's MUST); fewer than announced is a WARN (the capacity should be documented,
    which the tool cannot see). R-4.4.7-08: the recorder uses aC!-type commands: each one in
    ``asked`` (what the scenarios told it to send) must be on the wire."""
    tally = Tally(("R-4.4.7-07", "R-4.4.7-08"))
    started = {m.start.text for m in taken}
    for text in asked:
        if parse_command(text).kind is Kind.CONCURRENT and text not in started:
            tally.fail("R-4.4.7-08", escape(text), f"asked for {escape(text)}, never sent it")
    for m in taken:
        if m.kind is not Kind.CONCURRENT:
            continue
        where = escape(m.start.text)
        have = len(m.values())
        tally.observe(where, ids=["R-4.4.7-08"])
        if not have and m.count and not _ended_on_problem(m):  # completeness: R-4.4.8-05
            tally.fail("R-4.4.7-08", where, f"read none of the {m.count} values")
        if m.count <= MIN_CONCURRENT_STORE:
            continue
        tally.observe(where, ids=["R-4.4.7-07"])
        if have < MIN_CONCURRENT_STORE:
            tally.fail(
                "R-4.4.7-07", where, f"read {have} of {m.count} values (at least 20 are due)"
            )
        elif have < m.count:
            tally.fail(
                "R-4.4.7-07",
                where,
                f"read {have} of {m.count} values (fewer than announced)",
                warning=True,
            )
    return tally.findings("values read")


def _ended_on_problem(m: Taken) -> bool:
    return _collection_end(m)[1] is not None


def judge_high_volume(taken: Sequence[Taken], is_v14: bool) -> list[Finding]:
    """R-5.1-04: after aHA! data commands go past aD9! as needed, without leading zeros.
    R-5.2-08: after aHB! aDBn! commands in 7E1, packets checked, collection stops at the empty
    packet or once every value is in. R-5.4-01: a v1.4 recorder issues aHA! and aHB! and reads
    their data back."""
    tally = Tally(("R-5.1-04", "R-5.2-08", "R-5.4-01"))
    used = {Kind.HIGH_VOLUME_ASCII: False, Kind.HIGH_VOLUME_BINARY: False}
    for m in taken:
        if m.kind not in used:
            continue
        where = escape(m.start.text)
        have = len(m.values())
        used[m.kind] = used[m.kind] or have > 0
        rid = "R-5.1-04" if m.kind is Kind.HIGH_VOLUME_ASCII else "R-5.2-08"
        tally.observe(where, ids=[rid])
        zeros = [s for s, _ in m.data if (d := s.data_index) and d[2] != str(d[1])]
        if zeros:
            tally.fail(rid, where, f"{escape(zeros[0].text)} has leading zeros")
        if m.kind is Kind.HIGH_VOLUME_BINARY:
            parity = [e for s, _ in m.data for e in s.chars if not e.parity_ok]
            if parity:
                tally.fail(rid, where, "a DB command was not sent in 7E1 (parity)")
            last, problem, empty = _collection_end(m)
            if problem is None and have < m.count and not empty:
                tally.fail(rid, where, f"stopped with {have} of {m.count} values, no empty packet")
            extra = _after_done(m)
            if extra:
                tally.fail(rid, where, f"{escape(extra.text)} sent after every value was in")
        else:
            last, problem, _ = _collection_end(m)
            if problem is None and have < m.count:
                tally.fail(
                    rid,
                    where,
                    f"stopped at {escape(last.text) if last else 'D0'} with "
                    f"{have} of {m.count} values",
                )
    if is_v14:
        for kind, ok in used.items():
            tally.observe(kind.value.replace("a", "", 1), ids=["R-5.4-01"])
            if not ok:
                tally.fail("R-5.4-01", str(kind), f"{kind} was not issued or its data not read")
    else:
        tally.not_applicable("R-5.4-01", "the recorder does not claim v1.4")
    return tally.findings("conforms")


def _after_done(m: Taken) -> Sent | None:
    """A DB command sent after the values were complete (or after the empty packet)."""
    total = 0
    for i, (s, problem) in enumerate(m.data):
        if problem is not None:
            continue
        packet = parse_binary_packet(decode_8n1(s.answer))
        total += len(packet.values)
        if total >= m.count or not packet.values:
            later = [t for t, _ in m.data[i + 1 :] if t.text != s.text]
            return later[0] if later else None
    return None


# -- judges: retries ------------------------------------------------------------------------------
def judge_retries(line: Line, uncertainty: float) -> list[Finding]:
    """Section 7.2 over every command whose reply was missing or invalid: R-7.2-01 it was sent
    again; R-7.2-02 after no reply, a retry without a break 16.67-87 ms after the command;
    R-7.2-03 a sequence given up had two retries, one more than 100 ms after its break;
    R-7.2-04 (SHOULD) three sequences before giving up; R-7.2-05 every missing or invalid
    reply triggered a retry; R-7.2-06 the retry waited for the invalid reply to end."""
    window: list[Finding] = []
    third: list[Finding] = []
    ends: list[Finding] = []
    tally = Tally(("R-7.2-01", "R-7.2-04", "R-7.2-05"))
    retried_somewhere = False
    for group in tries(line, uncertainty):
        if all(a.problem is None for a in group.attempts):
            continue
        where = escape(group.text)
        tally.observe(where, ids=["R-7.2-05"])
        retried_somewhere = retried_somewhere or len(group.attempts) > 1
        # Given up, as opposed to accepted: silence cannot be mistaken for a valid reply, and
        # a command sent again shows the recorder found the reply invalid. A garbled reply
        # sent once may have been accepted: that is R-7.2-05's (and R-4.4.12-07's) finding.
        gave_up = group.attempts[-1].problem is NO_REPLY or len(group.attempts) > 1
        if gave_up:
            tally.observe(where, ids=["R-7.2-01"])
        if len(group.attempts) == 1 and gave_up:
            tally.fail("R-7.2-01", where, f"not sent again after {group.attempts[0].problem}")
        sequences = group.sequences()
        for n, seq in enumerate(sequences):
            later = sequences[n + 1][0] if n + 1 < len(sequences) else None
            for k, a in enumerate(seq):
                if a.problem is None:
                    continue
                nxt = seq[k + 1] if k + 1 < len(seq) else None
                follower = nxt or later
                if follower is None and len(seq) < 3:
                    tally.fail("R-7.2-05", where, f"{a.problem} at {_at(a.sent)}, then no retry")
                if a.problem is NO_REPLY:
                    if nxt is not None:
                        window.append(
                            judge_window(
                                "R-7.2-02",
                                "retry after no reply",
                                nxt.sent.first_char - a.sent.end,
                                uncertainty,
                                low=RETRY_MIN,
                                high=RETRY_MAX,
                                evidence=[_at(nxt.sent)],
                            )
                        )
                    elif k == 0:
                        window.append(
                            Finding(
                                "R-7.2-02",
                                Verdict.FAIL,
                                f"no retry without a break after no reply to {_at(a.sent)}",
                            )
                        )
                elif follower is not None:
                    ends.append(
                        _retry_after_reply(line, a.sent, follower.sent, a.problem, uncertainty)
                    )
            if any(a.problem is None for a in seq) or not gave_up:
                continue
            label = f"{where} sequence {n + 1}"
            retries = seq[1:]
            if len(retries) < 2:
                third.append(
                    Finding(
                        "R-7.2-03", Verdict.FAIL, f"{label}: {len(retries)} retries, then no more"
                    )
                )
                continue
            brk = seq[0].sent.break_event or _last_break_before(line, seq[0].sent)
            if brk is not None:
                third.append(
                    judge_window(
                        "R-7.2-03",
                        "latest retry after the end of the break",
                        max(r.sent.first_char for r in retries) - brk.end,
                        uncertainty,
                        low=RETRY_AFTER_BREAK,
                        evidence=[label],
                    )
                )
        if not group.succeeded and gave_up:
            tally.observe(where, ids=["R-7.2-04"])
            if len(sequences) < 3:
                tally.fail(
                    "R-7.2-04",
                    where,
                    f"gave up after {len(sequences)} break+command+retries sequence(s)",
                    warning=True,
                )
        elif len(sequences) > 1:
            tally.observe(where, ids=["R-7.2-04"])
    if retried_somewhere:
        tally.observe("the run", ids=["R-7.2-01"])
    return [
        *tally.findings("retried as due"),
        combine("R-7.2-02", window, "retry after no reply"),
        combine("R-7.2-03", third, "unanswered sequence"),
        combine("R-7.2-06", ends, "retry after an invalid reply"),
    ]


def _retry_after_reply(
    line: Line, sent: Sent, retry: Sent, problem: ReplyProblem | None, uncertainty: float
) -> Finding:
    """R-7.2-06: marking between the end of the invalid reply and the retry; negative when
    the sensor was still sending as the recorder took the line again."""
    mine = {id(c) for s in line.sent for c in s.chars}
    reply = [c for c in line.chars if id(c) not in mine and sent.end <= c.start < retry.end]
    reply_end = max((c.end for c in reply), default=sent.end)
    return judge_window(
        "R-7.2-06",
        "retry after the end of the invalid reply",
        retry.start - reply_end,
        uncertainty,
        low=0.0,
        tolerance=0.0,
        evidence=[f"{_at(retry)} after {problem}"],
    )


def _last_break_before(line: Line, sent: Sent) -> Event | None:
    before = [b for b in line.breaks if b.end <= sent.start]
    return before[-1] if before else None


def judge_crc_checked(
    line: Line, uncertainty: float, logged: dict[str, list[str]] | None, truth: list[str]
) -> list[Finding]:
    """R-4.4.12-07: a reply whose CRC does not match is treated as invalid: it is retried, and
    (when the recorder reports what it logged) its values are not logged."""
    tally = Tally(("R-4.4.12-07",))
    for group in tries(line, uncertainty):
        for k, a in enumerate(group.attempts):
            if a.problem is None or a.problem.reason is not Reason.CRC_WRONG:
                continue
            where = escape(group.text)
            tally.observe(where)
            if k + 1 >= len(group.attempts):
                tally.fail("R-4.4.12-07", where, f"accepted a reply whose {a.problem}")
    if logged is not None and truth:
        for command, values in logged.items():
            if values and values != truth[: len(values)]:
                tally.fail(
                    "R-4.4.12-07",
                    escape(command),
                    f"logged {' '.join(values[:4])}..., the sensor's values are "
                    f"{' '.join(truth[:4])}...",
                )
    return tally.findings("CRC mismatches retried, correct values logged")


# -- judges: what the recorder can do ---------------------------------------------------------
def _answered(line: Line, text: str, uncertainty: float) -> Sent | None:
    """The transmission of ``text`` that drew a valid reply, if any."""
    crc = crc_context(line)
    for i, s in enumerate(line.sent):
        if s.text == text and reply_problem(s, crc[i], uncertainty) is None:
            return s
    return None


def judge_commands_issued(
    line: Line, asked: Sequence[str], uncertainty: float, rid: str = "R-4.4-02"
) -> Finding:
    """``rid`` (R-4.4-02 by default): every command the recorder was asked to use went out and
    drew a valid reply; for measurements, every announced value was read."""
    missing = [text for text in asked if _answered(line, text, uncertainty) is None]
    taken = {m.start.text: m for m in measurements(line, uncertainty)}
    short = [
        f"{escape(t)} ({len(m.values())} of {m.count} values)"
        for t, m in taken.items()
        if t in asked and len(m.values()) < m.count
    ]
    if missing or short:
        parts = []
        if missing:
            parts.append("never answered validly: " + ", ".join(escape(t) for t in missing))
        if short:
            parts.append("data not read: " + ", ".join(short))
        return Finding(rid, Verdict.FAIL, "; ".join(parts))
    return Finding(
        rid,
        Verdict.PASS,
        f"{len(asked)} commands issued and answered: " + " ".join(escape(t) for t in asked),
        observed=len(asked),
    )


def judge_addresses(line: Line, uncertainty: float) -> list[Finding]:
    """R-4.3-03: the recorder polls every address 0-9. R-4.3-04 (MAY): letters as addresses."""
    polled = {s.address for s in line.sent if _answered(line, s.text, uncertainty) is s}
    digits = [a for a in "0123456789" if a not in polled]
    r3 = (
        Finding("R-4.3-03", Verdict.FAIL, f"addresses never polled successfully: {digits}")
        if digits
        else Finding(
            "R-4.3-03",
            Verdict.PASS,
            "sensors at 0-9 each polled and answered",
            observed=len(polled),
        )
    )
    letters = sorted(a for a in polled if a.isalpha())
    commands = [s for s in line.sent if s.text.endswith("!")]  # R-4.4-04 judges the rest
    foreign = sorted({s.address for s in commands if s.address not in ADDRESS_CHARS} - {"?"})
    if foreign:  # a MAY rule: the Finding caps this at WARN
        shown = ", ".join(f"'{escape(a)}'" for a in foreign)
        r4 = Finding("R-4.3-04", Verdict.FAIL, f"addressed {shown}, not an address", decision="A17")
    elif letters:
        r4 = Finding(
            "R-4.3-04",
            Verdict.PASS,
            f"letter addresses used: {' '.join(letters)}",
            observed=len(letters),
        )
    else:
        r4 = Finding("R-4.3-04", Verdict.NA, "the recorder did not use letter addresses (optional)")
    return [r3, r4]


def judge_transparent(
    line: Line,
    asked: Sequence[str],
    uncertainty: float,
    relayed: dict[str, str] | None,
) -> list[Finding]:
    """R-4.4.14-01: each host command goes out whole, after a break, and (when the recorder
    reports it) the sensor's reply is relayed unchanged. R-4.4.14-02: basic, extended and
    metadata commands pass unchanged. R-4.4.13-03: extended commands start with the address
    and end with ``!``. R-6.3-01: metadata commands pass through (what a recorder that does
    not understand metadata must at least do)."""
    mechanism = Tally(("R-4.4.14-01",))
    unchanged = Tally(("R-4.4.14-02", "R-4.4.13-03", "R-6.3-01"))
    sent_texts = [s.text for s in line.sent]
    for text in asked:
        where = escape(text)
        cmd = parse_command(text)
        ids = ["R-4.4.14-02"]
        if cmd.kind is Kind.EXTENDED:
            ids.append("R-4.4.13-03")
        if cmd.kind in (Kind.METADATA, Kind.IDENTIFY_MEASUREMENT):
            ids.append("R-6.3-01")
        unchanged.observe(where, ids=ids)
        matching = [s for s in line.sent if s.text == text]
        if not matching:
            near = [t for t in sent_texts if t[:1] == text[:1]]
            instead = (
                f"sent instead: {', '.join(repr(escape(t)) for t in near[:3])}"
                if near
                else f"nothing starting with {escape(text[:1])!r} was sent"
            )
            for rid in ids:
                unchanged.fail(rid, where, f"not on the wire as typed ({instead})")
            continue
        mechanism.observe(where)  # only a command that went out shows how it went out
        first = matching[0]
        if first.break_event is None:
            mechanism.fail("R-4.4.14-01", where, "sent without a break to wake the bus")
        if relayed is not None:
            got = relayed.get(text)
            want = decode_7e1(matching[-1].answer)
            if got is not None and got != want:
                mechanism.fail(
                    "R-4.4.14-01",
                    where,
                    f"relayed '{escape(got[:40])}', the sensor sent '{escape(want[:40])}'",
                )
    return [*mechanism.findings("passed through"), *unchanged.findings("passed unchanged")]


def judge_multiline_end(
    line: Line, relayed: dict[str, str] | None, uncertainty: float
) -> list[Finding]:
    """R-4.4.13.1-04 (SHOULD): multi-line text without ETX is complete once no further line
    starts within 150 ms: the recorder neither talks over a line that may still come nor
    loses the lines it got."""
    found: list[Finding] = []
    for i, s in enumerate(line.sent):
        answer = s.answer
        if len(answer) < 2 or answer[1].char7 != STX or answer[-1].char7 != 0x0A:
            continue
        nxt = line.sent[i + 1] if i + 1 < len(line.sent) else None
        where = [f"text in reply to {_at(s)}"]
        if nxt is not None:
            f = judge_window(
                "R-4.4.13.1-04",
                "marking after the last line before the recorder spoke again",
                nxt.start - answer[-1].end,
                uncertainty,
                low=MULTILINE_GAP_MAX,
                should=True,
                evidence=where,
            )
            found.append(f)
        if relayed is not None and s.text in relayed:
            lines = decode_7e1(answer).count("\r\n")
            got = relayed[s.text].count("\r\n")
            if got < lines:
                found.append(
                    Finding(
                        "R-4.4.13.1-04",
                        Verdict.WARN,
                        f"relayed {got} of {lines} lines",
                        evidence=where,
                    )
                )
    return [combine("R-4.4.13.1-04", found, "multi-line text without ETX")]
