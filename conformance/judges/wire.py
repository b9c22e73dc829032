"""Judges over the whole transcript: response timing, character gaps, framing of every reply.

The transcript is cut into segments: a command the tool sent (with the break before it, if
any), the DUT's reply to it (the run of characters that starts soon after the command), and
anything the DUT sent later before the tool spoke again (service requests, chatter).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from ..protocol.commands import CommandError, Kind, parse_command
from ..protocol.timing import (
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    NO_BREAK_WINDOW,
    RESPONSE_START_MAX,
    RESPONSE_START_MIN,
    TOLERANCE,
)
from ..transcript import TOOL, Event, EventKind, escape
from ..verdicts import Finding, Verdict
from .timing import (
    StampUncertainty,
    combine_local,
    judge_window,
    stamp_uncertainty,
    sustained,
)

REPLY_SEARCH = NO_BREAK_WINDOW  # a DUT run starting later than this is not a reply
RUN_GAP = 0.05  # characters closer than this belong to one run (lenient, for evidence)
LINE_RUN_GAP = 1.0  # a late next line of multi-line text still belongs to its reply


@dataclass
class Segment:
    break_event: Event | None
    command: list[Event]
    reply: list[Event] = field(default_factory=list)
    later: list[Event] = field(default_factory=list)
    contention: list[Event] = field(default_factory=list)  # DUT talked over the command
    text: str = ""  # the command as text, filled in by :func:`segments`
    binary_reply: bool = False  # replies to aDBn! are 8N1 packets (no 7E1, no CR LF)

    @property
    def command_end(self) -> float:
        return self.command[-1].end

    @property
    def multiline(self) -> bool:
        """A reply starting ``a<STX>`` is multi-line text (decision A10)."""
        return len(self.reply) > 1 and self.reply[1].char7 == 0x02


def _is_binary_data(text: str) -> bool:
    try:
        return parse_command(text).kind is Kind.BINARY_DATA
    except CommandError:
        return False


def segments(events: Iterable[Event]) -> list[Segment]:
    result: list[Segment] = []
    pending_break: Event | None = None
    current: Segment | None = None
    for e in events:
        if e.kind is EventKind.NOTE:
            continue
        if e.origin == TOOL:
            if e.kind is EventKind.BREAK:
                pending_break, current = e, None
                continue
            if current is None or current.reply or current.later or current.text.endswith("!"):
                current = Segment(pending_break, [e], text=chr(e.char7))
                result.append(current)
                pending_break = None
            else:
                current.command.append(e)
                current.text += chr(e.char7)
            current.binary_reply = current.text.endswith("!") and _is_binary_data(current.text)
            continue
        if current is None:
            continue  # DUT chatter before any command
        if not current.text.endswith("!") or e.start < current.command_end:
            current.contention.append(e)  # not a reply: it overlapped the command
            continue
        _place_dut_char(current, e)
    return result


def _place_dut_char(seg: Segment, e: Event) -> None:
    if seg.later:
        seg.later.append(e)
        return
    if not seg.reply:
        if e.start - seg.command_end <= REPLY_SEARCH:
            seg.reply.append(e)
        else:
            seg.later.append(e)
        return
    last = seg.reply[-1]
    ended = not seg.binary_reply and last.char7 == 0x0A and not seg.multiline
    # the next line of multi-line text may come late (R-4.4.13.1-03 judges how late)
    allowed = LINE_RUN_GAP if seg.multiline and last.char7 == 0x0A else RUN_GAP
    if ended or e.start - last.end > allowed:
        seg.later.append(e)
    else:
        seg.reply.append(e)


def runs(events: list[Event]) -> list[list[Event]]:
    """Split DUT characters into runs separated by more than :data:`RUN_GAP` of marking."""
    out: list[list[Event]] = []
    for e in events:
        if out and e.start - out[-1][-1].end <= RUN_GAP:
            out[-1].append(e)
        else:
            out.append([e])
    return out


# -- timing ---------------------------------------------------------------------------------
def judge_response_start(
    segs: list[Segment], uncertainty: float | StampUncertainty
) -> list[Finding]:
    """R-7.0-09 (not before 7.93 ms) and R-7.0-10 (within 15.40 ms) for every reply, each
    with the uncertainty of the stamps it rests on (the command's last, the reply's first)."""
    stamps = stamp_uncertainty(uncertainty)
    early, late = [], []
    for seg in segs:
        if not seg.reply:
            continue
        delay = seg.reply[0].start - seg.command_end
        u = stamps.between(seg.command[-1].start, seg.reply[0].end)
        tainted = u > stamps.base
        where = [f"reply to {escape(seg.text)} at t={seg.command_end:.4f} s"]
        early.append(
            (
                judge_window(
                    "R-7.0-09",
                    "first response start bit after the command",
                    delay,
                    u,
                    low=CHAR_TIME,
                    tolerance=TOLERANCE,
                    evidence=where,
                ),
                tainted,
            )
        )
        late.append(
            (
                judge_window(
                    "R-7.0-10",
                    "first response start bit after the command",
                    delay,
                    u,
                    high=RESPONSE_START_MAX,
                    evidence=where,
                ),
                tainted,
            )
        )
    _ = RESPONSE_START_MIN  # = CHAR_TIME - TOLERANCE, the derived window's lower edge
    real = stamps.local is not None
    return [
        combine_local("R-7.0-09", early, "reply", real_time=real),
        combine_local("R-7.0-10", late, "reply", real_time=real),
    ]


def reply_gaps(segs: list[Segment]) -> list[tuple[float, str]]:
    """Every marking gap between consecutive characters of one DUT run, with its context."""
    return [(gap, where) for gap, where, _a, _b in _gaps(segs)]


def _gaps(segs: list[Segment]) -> list[tuple[float, str, Event, Event]]:
    gaps = []
    for seg in segs:
        for run in runs(seg.reply) + runs(seg.later):
            for a, b in zip(run, run[1:], strict=False):
                if seg.multiline and a.char7 == 0x0A:
                    continue  # between lines of multi-line text: R-4.4.13.1-03's 150 ms
                gaps.append((b.start - a.end, f"in reply to {escape(seg.text)}", a, b))
    return gaps


def judge_gaps(segs: list[Segment], uncertainty: float | StampUncertainty) -> list[Finding]:
    """R-7.0-12: at most 1.66 ms of marking between characters (no tolerance), and R-7.0-01:
    a gap inside the ±0.40 ms band above 1.66 ms uses a tolerance the rule does not grant.
    Each gap carries the uncertainty of the two stamps it rests on."""
    stamps = stamp_uncertainty(uncertainty)
    observed = []
    for gap, where, a, b in _gaps(segs):
        u = stamps.between(a.start, b.end)
        finding = judge_window(
            "R-7.0-12",
            "marking between response characters",
            gap,
            u,
            high=INTER_CHAR_GAP_MAX,
            tolerance=0.0,
            evidence=[where],
        )
        observed.append((finding, u > stamps.base))
    gap_finding = combine_local(
        "R-7.0-12", observed, "character gap", real_time=stamps.local is not None
    )
    tolerance_finding = _judge_tolerance_use(reply_gaps(segs), stamps.base)
    return [gap_finding, tolerance_finding]


def _judge_tolerance_use(gaps: list[tuple[float, str]], uncertainty: float) -> Finding:
    """R-7.0-01 for the one limit without tolerance: a gap surely inside (1.66, 2.06] ms leans
    on a ±0.40 ms the rule does not grant (FAIL); one that only might be there, given the
    link's uncertainty, is INCONCLUSIVE; a gap surely beyond 2.06 ms is R-7.0-12's alone."""
    band_lo, band_hi = INTER_CHAR_GAP_MAX, INTER_CHAR_GAP_MAX + TOLERANCE
    sure = [(g, w) for g, w in gaps if g - uncertainty > band_lo and g + uncertainty <= band_hi]
    maybe = [(g, w) for g, w in gaps if g + uncertainty > band_lo and g - uncertainty <= band_hi]
    if sure:
        gap, where = sure[0]
        return Finding(
            "R-7.0-01",
            Verdict.FAIL,
            f"gap of {gap * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} relies on the ±0.40 ms "
            f"tolerance, which the 1.66 ms character gap does not have ({len(sure)} such "
            "gap(s))",
            evidence=[where],
            measured_ms=round(gap * 1e3, 3),
            limit_ms=1.66,
            uncertainty_ms=round(uncertainty * 1e3, 3),
        )
    if maybe:
        gap, where = maybe[0]
        return Finding(
            "R-7.0-01",
            Verdict.INCONCLUSIVE,
            f"{len(maybe)} gap(s) such as {gap * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} may lie "
            "in the 1.66..2.06 ms band, where no tolerance applies",
            evidence=[where],
            measured_ms=round(gap * 1e3, 3),
            limit_ms=1.66,
            uncertainty_ms=round(uncertainty * 1e3, 3),
        )
    if not gaps:
        return Finding("R-7.0-01", Verdict.INCONCLUSIVE, "no character gap observed")
    return Finding(
        "R-7.0-01",
        Verdict.PASS,
        f"{len(gaps)} character gaps: none leans on a tolerance the rule does not grant; "
        "±0.40 ms applied to every other limit",
        observed=len(gaps),
    )


def judge_bit_rate(segs: list[Segment], uncertainty: float | StampUncertainty) -> Finding:
    """R-4.1-01 (decision A14: 1200 baud ±2%). Back-to-back characters start one frame apart,
    so the shortest start-to-start spacing inside a reply is at least one frame (8.17 ms at
    +2%). A shorter spacing proves the rate too high. A rate too low cannot be told apart from
    an allowed inter-character gap unless some characters come back to back (spacing within
    the ±2% band), so without such a pair the verdict is INCONCLUSIVE, never a guess."""
    stamps = stamp_uncertainty(uncertainty)
    uncertainty = stamps.base
    spacings = []
    fast = []  # spacings surely too short even with the stamps' local uncertainty
    for seg in segs:
        for run in runs(seg.reply) + runs(seg.later):
            for a, b in zip(run, run[1:], strict=False):
                spacings.append((b.start - a.start, seg.text))
                if b.start - a.start + 2 * stamps.between(a.start, b.end) < CHAR_TIME * 0.98:
                    fast.append((b.start - a.start, seg.text))
    if not spacings:
        return Finding("R-4.1-01", Verdict.INCONCLUSIVE, "no multi-character reply observed")
    shortest, text = min(spacings)
    low, high = CHAR_TIME * 0.98, CHAR_TIME * 1.02
    where = [f"in reply to {escape(text)}"]
    if stamps.local is not None and shortest + 2 * uncertainty < low:
        if not sustained(len(fast), len(spacings)):  # a few bursts of a stalling host
            return Finding(
                "R-4.1-01",
                Verdict.INCONCLUSIVE,
                f"{len(fast)} of {len(spacings)} character spacings are shorter than a frame "
                f"(shortest {shortest * 1e3:.2f} ms); too few, or too near irregular stamps, "
                "to tell a fast bit rate from bursts of the link",
                evidence=where,
                observed=len(spacings),
            )
        shortest, text = min(fast)
        where = [f"in reply to {escape(text)}"]
    if shortest + 2 * uncertainty < low:
        return judge_window(
            "R-4.1-01",
            "shortest character start-to-start spacing",
            shortest,
            2 * uncertainty,
            low=low,
            tolerance=0.0,
            evidence=where,
            decision="A14",
        )
    finding = judge_window(
        "R-4.1-01",
        "shortest character start-to-start spacing",
        shortest,
        2 * uncertainty,
        low=low,
        high=high,
        tolerance=0.0,
        evidence=where,
        decision="A14",
    )
    if finding.verdict is Verdict.FAIL:  # too slow or gapped: not decidable, see docstring
        finding.verdict = Verdict.INCONCLUSIVE
        finding.detail += " (no back-to-back characters: rate and gaps cannot be separated)"
    baud = 10 / shortest if shortest > 0 else float("inf")
    finding.detail += f"; about {baud:.0f} baud from {len(spacings)} spacings"
    return finding


# -- framing of every reply -------------------------------------------------------------------
def _reply_address(seg: Segment) -> str | None:
    """The address a reply to this command must start with (None: any address)."""
    text = seg.text
    if text.startswith("?") or len(text) < 2:
        return None  # a wildcard: the sensor answers with its own address
    if len(text) == 4 and text[1] == "A" and text.endswith("!"):
        return None  # aAb!: the new address, or the old one if the change failed
    return text[0]


def judge_framing(segs: list[Segment]) -> list[Finding]:
    """R-4.1-02 (7E1 parity), R-4.2-02 (printable), R-4.2-03 (>= 3 chars, CR LF), R-4.3-01
    (the responding sensor's address first) over every ASCII reply and service request."""
    from ..protocol.responses import split_line  # local: wire must not depend on parsers
    from .tally import Tally

    tally = Tally(("R-4.1-02", "R-4.2-02", "R-4.2-03", "R-4.3-01"))
    last_address = None
    for i, seg in enumerate(segs):
        if seg.reply:
            last_address = seg.reply[0].char7
        # unsolicited characters cut off by the next command collided with it: what is left
        # of them says nothing about framing (the collision is judged by the rule it breaks)
        later = [] if i + 1 < len(segs) and segs[i + 1].contention else runs(seg.later)
        reply = [seg.reply] if seg.reply and not seg.binary_reply else []
        chunks = reply + later
        for n, chunk in enumerate(chunks):
            label = f"{'reply to' if n == 0 and seg.reply else 'later, after'} {escape(seg.text)}"
            bad = [e for e in chunk if not e.parity_ok]
            tally.observe(label, ids=["R-4.1-02"])
            if bad:
                tally.fail(
                    "R-4.1-02",
                    label,
                    f"{len(bad)} character(s) with wrong parity, first 0x{bad[0].wire:02X}",
                )
            text = "".join(chr(e.char7) for e in chunk)
            if seg.multiline and n == 0:  # decision A10: each line is framed on its own
                lines = text.replace("\x02", "", 1).rstrip("\x03").split("\r\n")
                for line in lines[:-1]:
                    tally.observe(label, split_line(line + "\r\n")[1], ids=["R-4.2-02", "R-4.2-03"])
                if lines[-1] == "":  # complete: the checks below look at the first line
                    text = lines[0] + "\r\n"
            stripped = text.rstrip("\r\n")
            crc_positions = (
                3
                if len(stripped) >= 4 and all(0x40 <= ord(c) <= 0x7F for c in stripped[-3:])
                else 0
            )
            body, framing = split_line(text, crc_positions=crc_positions)
            tally.observe(label, framing, ids=["R-4.2-02", "R-4.2-03"])
            expected = _reply_address(seg) if n == 0 and seg.reply else None
            if n > 0 or not seg.reply:  # unsolicited: a service request from the sensor
                expected = chr(last_address) if last_address else None
            tally.observe(label, ids=["R-4.3-01"])
            if expected and body[:1] != expected:
                tally.fail(
                    "R-4.3-01",
                    label,
                    f"reply '{escape(text)}' starts with "
                    f"'{escape(body[:1])}', not the address '{expected}'",
                )
    return tally.findings()
