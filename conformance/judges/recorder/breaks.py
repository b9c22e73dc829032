"""Judges of the recorder's breaks: their length and the marking after them (R-7.0-02/06),
and when a break is due (R-7.0-17, R-7.1-01)."""

from __future__ import annotations

from ...protocol.timing import BREAK_MIN, MARKING_AFTER_BREAK, NO_BREAK_WINDOW
from ...verdicts import Finding, Verdict
from ...view.segments import TranscriptView, Transmission
from ..timing import MeasuredAsJudged, Repeats, Window, judge_window
from .common import SR_KINDS, combine, own_uncertainty
from .measurements import service_request_end

#: R-7.0-02's and R-7.0-06's windows, worked out once for the many breaks of a recording
BREAK_LENGTH = Window("R-7.0-02", "break length", low=BREAK_MIN)
MARKING = Window("R-7.0-06", "marking after the break", low=MARKING_AFTER_BREAK)


def judge_breaks(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-7.0-02: every break lasts at least 12 ms. R-7.0-06: after a break the recorder marks
    at least 8.33 ms before the first start bit of its command (both ±0.40 ms)."""
    # a break read by a UART as a NUL (a listen-only monitor) is known to have lasted only
    # at least a frame: its length, and so where it ended, carries that event's own doubt
    # one judged interval each, its finding made only where the verdict shows it (an hour
    # of a busy bus holds 15,000 breaks)
    # an interval equal to one judged before is that one again (Repeats), so the breaks
    # hold one object per distinct length and marking
    lengths: list[MeasuredAsJudged] = []
    seen: Repeats[MeasuredAsJudged] = Repeats()
    for b in line.breaks:
        length, u = b.duration, max(uncertainty, b.duration_uncertainty or 0.0)
        lengths.append(
            seen.first(length, u)
            or seen.keep(MeasuredAsJudged(BREAK_LENGTH, length, u, [f"break at t={b.start:.3f} s"]))
        )
    markings: list[MeasuredAsJudged] = []
    seen = Repeats()
    for s in line.transmissions:
        if s.break_event is None:
            continue
        marking = s.first_char - s.break_event.end
        u = max(own_uncertainty(uncertainty, s.chars[0]), s.break_event.duration_uncertainty or 0.0)
        markings.append(
            seen.first(marking, u)
            or seen.keep(MeasuredAsJudged(MARKING, marking, u, [f"before {s.at()}"]))
        )
    return [combine("R-7.0-02", lengths, "break"), combine("R-7.0-06", markings, "marking")]


def judge_break_rules(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-7.0-17: a break before every command to a different sensor than the last one, or after
    more than 87 ms of marking. R-7.1-01: ``aD0!`` without a break only within 87 ms of the
    service request."""
    rule17: list[Finding] = []
    rule71: list[Finding] = []
    previous: Transmission | None = None
    for s in line.transmissions:
        if previous is not None and previous.part != s.part:
            previous = None  # a new scenario: the line was idle and the sensors are new
        if s.break_event is None:
            where = [f"before {s.at()}"]
            if previous is None or previous.address != s.address:
                who = "no earlier command" if previous is None else f"last was {previous.text}"
                rule17.append(
                    Finding(
                        "R-7.0-17",
                        Verdict.FAIL,
                        f"no break before {s.at()}, a new sensor ({who})",
                        evidence=where,
                        observed=1,
                    )
                )
            else:
                quiet = s.first_char - (line.previous_activity(s) or float("-inf"))
                rule17.append(
                    judge_window(
                        "R-7.0-17",
                        "marking before a command sent without a break",
                        quiet,
                        own_uncertainty(uncertainty, s.chars[0], previous.chars[-1]),
                        high=NO_BREAK_WINDOW,
                        evidence=where,
                    )
                )
            if previous is not None and _follows_service_request(previous, s):
                sr_end = service_request_end(previous.after, s.address)
                assert sr_end is not None
                rule71.append(
                    judge_window(
                        "R-7.1-01",
                        "aD0! without a break after the service request",
                        s.first_char - sr_end,
                        own_uncertainty(uncertainty, s.chars[0]),
                        high=NO_BREAK_WINDOW,
                        evidence=where,
                    )
                )
        elif previous is not None and _follows_service_request(previous, s):
            rule71.append(
                Finding(
                    "R-7.1-01",
                    Verdict.PASS,
                    f"a break before {s.at()} after the service request",
                    observed=1,
                )
            )
        previous = s
    return [
        combine("R-7.0-17", rule17, "command without a break")
        if rule17
        else Finding("R-7.0-17", Verdict.PASS, _all_broke(line), observed=len(line.transmissions)),
        combine("R-7.1-01", rule71, "aD0! after a service request"),
    ]


def _all_broke(line: TranscriptView) -> str:
    return f"all {len(line.transmissions)} commands were sent after a break"


def _follows_service_request(previous: Transmission, s: Transmission) -> bool:
    cmd = previous.command
    d = s.data_index
    return (
        cmd is not None
        and cmd.kind in SR_KINDS
        and d is not None
        and d[1] == 0
        and s.address == cmd.address
        and service_request_end(previous.after, cmd.address) is not None
    )
