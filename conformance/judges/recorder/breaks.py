"""Judges of the recorder's breaks: their length and the marking after them (R-7.0-02/06;
after a break the line held back, :func:`_after_held_back`), and when a break is due
(R-7.0-17, R-7.1-01)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from ...links.host_stall import Stall
from ...protocol.timing import BREAK_MIN, MARKING_AFTER_BREAK, NO_BREAK_WINDOW
from ...transcript import HELD_BACK, Event
from ...verdicts import Finding, Verdict
from ...view.segments import TranscriptView, Transmission
from ..timing import Counted, MeasuredAsJudged, Repeats, Window
from .common import SR_KINDS, combine, own_uncertainty
from .measurements import service_request_end
from .stalls import hold

#: R-7.0-02's and R-7.0-06's windows, worked out once for the many breaks of a recording
BREAK_LENGTH = Window("R-7.0-02", "break length", low=BREAK_MIN)
MARKING = Window("R-7.0-06", "marking after the break", low=MARKING_AFTER_BREAK)
#: R-7.0-17's window for a command to the same sensor without a break, R-7.1-01's for aD0!
#: without one after the service request (:class:`BreakRules`)
QUIET = Window("R-7.0-17", "marking before a command sent without a break", high=NO_BREAK_WINDOW)
AFTER_REQUEST = Window(
    "R-7.1-01", "aD0! without a break after the service request", high=NO_BREAK_WINDOW
)


def judge_breaks(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-7.0-02: every break lasts at least 12 ms. R-7.0-06: after a break the recorder marks
    at least 8.33 ms before the first start bit of its command (both ±0.40 ms)."""
    judge = Breaks(uncertainty, line.stalls)
    judge.add(line)
    return judge.findings()


class Breaks:
    """:func:`judge_breaks` over a recording read a window at a time (issue 22): each
    window's view :meth:`add`-ed in order, the findings those of the whole recording's view.
    What it keeps across windows is one observation per distinct length and marking
    (:class:`~..timing.Repeats`) and how often each came (:class:`~..timing.Counted`),
    never a window's events nor anything an observation."""

    def __init__(self, uncertainty: float, stalls: Sequence[Stall] = ()) -> None:
        self.uncertainty = uncertainty
        #: the tool's host stalls noted in the recording (a window's view holds none)
        self.stalls = list(stalls)
        # each judged interval counted by object, not listed (:class:`~..timing.Counted`)
        self.lengths = Counted()
        self.markings = Counted()
        self._lengths_seen: Repeats[MeasuredAsJudged] = Repeats()
        self._markings_seen: Repeats[MeasuredAsJudged] = Repeats()

    def add(self, line: TranscriptView) -> None:
        """The breaks and markings of ``line`` (the next window of the recording)."""
        # a break read by a UART as a NUL (a listen-only monitor) is known to have lasted only
        # at least a frame: its length, and so where it ended, carries that event's own doubt
        # one judged interval each, its finding made only where the verdict shows it (an hour
        # of a busy bus holds 15,000 breaks)
        # an interval equal to one judged before is that one again (Repeats), so the breaks
        # hold one object per distinct length and marking
        uncertainty = self.uncertainty
        stalls = self.stalls or line.stalls
        seen = self._lengths_seen
        for b in line.breaks:
            length, u = b.duration, max(uncertainty, b.duration_uncertainty or 0.0)
            judged = seen.first(length, u) or seen.keep(
                MeasuredAsJudged(BREAK_LENGTH, length, u, [f"break at t={b.start:.3f} s"])
            )
            held = b.text == HELD_BACK and judged.verdict is not Verdict.PASS
            if held:
                self.lengths.append(_held_back_short(judged, b))
            else:
                self.lengths.append(hold(stalls, judged, b.start, b.end))
        seen = self._markings_seen
        for s in line.transmissions:
            brk = s.break_event
            if brk is None:
                continue
            marking = s.first_char - brk.end
            u = max(own_uncertainty(uncertainty, s.chars[0]), brk.duration_uncertainty or 0.0)
            judged = seen.first(marking, u) or seen.keep(
                MeasuredAsJudged(MARKING, marking, u, [f"before {s.at()}"])
            )
            held = brk.text == HELD_BACK and judged.verdict is not Verdict.PASS
            if held:
                self.markings.append(_after_held_back(judged, s))
            else:
                self.markings.append(hold(stalls, judged, brk.end, s.first_char))

    def findings(self) -> list[Finding]:
        """R-7.0-02 and R-7.0-06 over everything added."""
        return [
            combine("R-7.0-02", self.lengths.alike(), "break"),
            combine("R-7.0-06", self.markings.alike(), "marking"),
        ]


def _held_back_short(judged: MeasuredAsJudged, b: Event) -> Finding:
    """A break the line held back (:data:`HELD_BACK`) that came out short of R-7.0-02:
    INCONCLUSIVE. The recorder began it while a sensor's character was on the line, and the
    line began it when that character ended and ended it where the recorder did (the kit keeps
    a break's end): its length on the line is less than the recorder held it, by how much
    the line does not say (the twenty-fourth round's ATtiny logger held 12.1 ms from inside a
    reply's character; the line kept 3.77 ms of it, and R-7.0-02 FAILed). One that holds
    still PASSes: holding back only ever shortens it."""
    return replace(
        judged.finding,
        verdict=Verdict.INCONCLUSIVE,
        detail=(
            f"{judged.detail}; a break the line held back for a sensor's character (the"
            " recorder began it while the character was on the line): the line began it"
            " later than the recorder did, so how long the recorder held it is not known"
        ),
        evidence=[f"break at t={b.start:.3f} s"],
    )


def _after_held_back(judged: MeasuredAsJudged, s: Transmission) -> Finding:
    """A marking short of R-7.0-06 after a break the line held back (:data:`HELD_BACK`):
    INCONCLUSIVE. The line moved the break's end later than the recorder asked, and a
    recorder that times its command from its own clock (a 1 ms tick, a deadline set when it
    began the break) marks less after the moved end than it would on a wire, where its break
    goes over the sensor's character; how much less is not known. One that holds still
    PASSes: the break only ever moves later, so the command comes no nearer to it on a wire."""
    return replace(
        judged.finding,
        verdict=Verdict.INCONCLUSIVE,
        detail=(
            f"{judged.detail}; after a break the line held back for a sensor's character (the"
            " recorder asked for it while the character was on the line): where the"
            " recorder's own timing puts its command after its break on a wire is not known"
        ),
        evidence=[f"before {s.at()}"],
    )


def judge_break_rules(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-7.0-17: a break before every command to a different sensor than the last one, or after
    more than 87 ms of marking. R-7.1-01: ``aD0!`` without a break only within 87 ms of the
    service request."""
    judge = BreakRules(uncertainty, line.stalls)
    judge.add(line)
    return judge.findings()


class BreakRules:
    """:func:`judge_break_rules` over a recording read a window at a time (issue 22): each
    window's view :meth:`add`-ed in order, the findings those of the whole recording's view.
    Carried from window to window: the transmission before (R-7.0-17 asks whether the next
    command is to the same sensor, R-7.1-01 whether it follows a service request), the
    window before (a command sent without a break first in its window is timed from the
    line's last activity there) and the count of commands (R-7.0-17's PASS says how many).
    Each command sent without a break is judged as one object per distinct interval
    (:class:`~..timing.MeasuredAsJudged`, :class:`~..timing.Repeats`), and a break after
    a service request as its first PASS again, kept in the order judged: a pointer a
    command, where a whole finding each was (memory27: a measuring bus's aD0! commands,
    ~50 kB a minute). Across a noted stall of the tool's host, or after spacing too short
    for a break, each is its own finding as before (:func:`~.stalls.hold` names the stall
    with that command's evidence; the short spacing's note is added to it)."""

    def __init__(self, uncertainty: float, stalls: Sequence[Stall] = ()) -> None:
        self.uncertainty = uncertainty
        #: the tool's host stalls noted in the recording (a window's view holds none)
        self.stalls = list(stalls)
        self.rule17: list[Finding | MeasuredAsJudged] = []
        self.rule71: list[Finding | MeasuredAsJudged] = []
        self._quiet_seen: Repeats[MeasuredAsJudged] = Repeats()
        self._after_request_seen: Repeats[MeasuredAsJudged] = Repeats()
        self._broke_after_request: Finding | None = None  # R-7.1-01's first PASS of a break
        self.previous: Transmission | None = None
        self.commands = 0
        #: the window before, for a command sent without a break first in its window: where
        #: its marking began (asked of that view only then: one window's events held)
        self._before: TranscriptView | None = None

    def _previous_activity(self, line: TranscriptView, s: Transmission) -> float | None:
        """:meth:`~.segments.TranscriptView.previous_activity` of ``s`` in the whole
        recording: in its window, or else where the window before ended."""
        found = line.previous_activity(s)
        if found is None and self._before is not None:
            found = self._before.previous_activity(s)
        return found

    def add(self, line: TranscriptView) -> None:
        """The commands of ``line`` (the next window of the recording)."""
        uncertainty, rule17, rule71 = self.uncertainty, self.rule17, self.rule71
        stalls = self.stalls or line.stalls
        previous = self.previous
        for s in line.transmissions:
            if previous is not None and previous.part != s.part:
                previous = None  # a new scenario: the line was idle and the sensors are new
            short = _too_short(s.break_event, uncertainty)
            if s.break_event is None or short:
                where = [f"before {s.at()}"]
                if previous is None or previous.address != s.address:
                    who = "no earlier command" if previous is None else f"last was {previous.text}"
                    missing = Finding(
                        "R-7.0-17",
                        Verdict.FAIL,
                        f"no break before {s.at()}, a new sensor ({who}){short}",
                        evidence=where,
                        observed=1,
                    )
                    # spacing too short to be a break, read across a stall: the recorder's
                    # break and its end came in one late read (truth32: a 0.00 ms break
                    # laid with the command the stall held back); no spacing at all stands
                    brk = s.break_event
                    if brk is not None and short:
                        missing = hold(stalls, missing, brk.start, brk.end)
                    rule17.append(missing)
                else:  # timed from the line's activity before it (before the short spacing)
                    began = self._previous_activity(line, s) or float("-inf")
                    quiet = s.first_char - began
                    u = own_uncertainty(uncertainty, s.chars[0], previous.chars[-1])
                    if stalls or short:
                        judged = QUIET.judge(quiet, u, where)
                        if short and judged.verdict is not Verdict.PASS:
                            judged.detail += short
                        rule17.append(hold(stalls, judged, began, s.first_char, NO_BREAK_WINDOW))
                    else:
                        rule17.append(_once(self._quiet_seen, QUIET, quiet, u, where))
                if previous is not None and _follows_service_request(previous, s):
                    sr_end = service_request_end(previous.after, s.address)
                    assert sr_end is not None
                    waited, u = s.first_char - sr_end, own_uncertainty(uncertainty, s.chars[0])
                    if stalls:
                        judged = AFTER_REQUEST.judge(waited, u, where)
                        rule71.append(hold(stalls, judged, sr_end, s.first_char, NO_BREAK_WINDOW))
                    else:
                        seen = self._after_request_seen
                        rule71.append(_once(seen, AFTER_REQUEST, waited, u, where))
            elif previous is not None and _follows_service_request(previous, s):
                # only the first one's detail is ever shown (a PASS with no figure is the
                # worst of the PASSes, and the first of the worst is shown): the rest count
                broke = self._broke_after_request
                if broke is None:
                    broke = self._broke_after_request = Finding(
                        "R-7.1-01",
                        Verdict.PASS,
                        f"a break before {s.at()} after the service request",
                        observed=1,
                    )
                rule71.append(broke)
            previous = s
        self.previous = previous
        self.commands += len(line.transmissions)
        self._before = line

    def findings(self) -> list[Finding]:
        """R-7.0-17 and R-7.1-01 over everything added."""
        return [
            combine("R-7.0-17", self.rule17, "command without a break")
            if self.rule17
            else Finding(
                "R-7.0-17", Verdict.PASS, _all_broke(self.commands), observed=self.commands
            ),
            combine("R-7.1-01", self.rule71, "aD0! after a service request"),
        ]


def _once(
    seen: Repeats[MeasuredAsJudged], window: Window, measured: float, u: float, where: list[str]
) -> MeasuredAsJudged:
    """``measured`` judged against ``window``: the first interval equal to it judged before
    (whose evidence a verdict shows: the first of the worst), else a new one kept."""
    return seen.first(measured, u) or seen.keep(MeasuredAsJudged(window, measured, u, where))


def _too_short(event: Event | None, uncertainty: float) -> str:
    """A note (``""``: none) for spacing before a command too short to be a break whatever the
    uncertainty (R-7.0-02 FAILs its length): no break for R-7.0-17 either, as a sensor need
    not take spacing under 12 ms for one (section 7.0; an STM32 HAL logger's send-break
    request holds 10 bits, 8.33 ms, and its sensors never woke)."""
    if event is None or event.duration >= BREAK_MIN or event.text == HELD_BACK:
        return ""  # a break, or one the line held back (how long it was held is not known)
    u = max(uncertainty, event.duration_uncertainty or 0.0)
    judged = MeasuredAsJudged(BREAK_LENGTH, event.duration, u, [f"break at t={event.start:.3f} s"])
    if judged.verdict is not Verdict.FAIL:
        return ""
    return (
        f" (the spacing before it, {event.duration * 1e3:.2f} ms, is too short to be a break:"
        " R-7.0-02)"
    )


def _all_broke(commands: int) -> str:
    return f"all {commands} commands were sent after a break"


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
