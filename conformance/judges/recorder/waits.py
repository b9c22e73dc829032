"""Judges of how the recorder waits for data: the service request or ttt, the line left
alone, no early data command (R-4.4.5-04..07, R-4.4.7-06).

A measurement the recorder tried again instead of collecting (no aD0!, the same command
next) across a noted stall of the tool's host is undecided naming the stall (truth33): the
played sensor's reply went out late, or an in-process recorder was paused over it, and a
recorder that gave up on a reply it did not get in time tried again as it must."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ...links.host_stall import Stall
from ...protocol.commands import CONCURRENT_KINDS
from ...transcript import escape
from ...verdicts import Finding, Verdict
from ...view.segments import Transmission
from ..tally import Tally
from ..timing import MeasuredAsJudged, Repeats, Window
from .common import (
    REACTION,
    REACTION_DECISION,
    SR_KINDS,
    beyond_reaction,
    combine,
)
from .measurements import ObservedMeasurement
from .stalls import tried_again


def judge_measure_waits(
    taken: Sequence[ObservedMeasurement], uncertainty: float, stalls: Sequence[Stall] = ()
) -> list[Finding]:
    """For aM!-type measurements with ttt > 0: R-4.4.5-04 no aD0! before the service request
    or ttt; R-4.4.5-07 the line left alone while waiting; R-4.4.5-05 aD0! promptly when the
    service request comes or ttt runs out (then after a break), and at once for ttt = 0
    (SHOULD); R-4.4.5-06 no traffic to other sensors until the data are in. ``stalls``: the
    tool's host stalls noted in the recording (:func:`_no_data_command`). One
    :class:`MeasureWaits` given each of ``taken`` in order."""
    waits = MeasureWaits(uncertainty, stalls)
    for m in taken:
        waits.take(m)
    return waits.findings()


class Waits:
    """One rule's waits after a measurement's reply, each judged against a window whose low
    limit is the measurement's ttt (:func:`~..timing.judge_window`), as the
    :class:`~..timing.MeasuredAsJudged` that aggregates as its finding does, one object per
    distinct interval of each ttt (:class:`~..timing.Repeats`: the first's evidence is
    the one a verdict shows), kept in the order judged (:func:`combine` and its
    distribution read them so: a pointer a measurement)."""

    def __init__(self, requirement: str, what: str) -> None:
        self.requirement, self.what = requirement, what
        self.judged: list[Finding | MeasuredAsJudged] = []
        self._by_ttt: dict[int, tuple[Window, Repeats[MeasuredAsJudged]]] = {}

    def judge(
        self, measured: float, uncertainty: float, ttt: int, evidence: Callable[[], str]
    ) -> None:
        """One wait of ``measured`` s after a reply that announced ``ttt``; ``evidence``
        makes its line (asked only for the first of its value)."""
        held = self._by_ttt.get(ttt)
        if held is None:
            window = Window(self.requirement, self.what, low=float(ttt))
            held = self._by_ttt[ttt] = (window, Repeats())
        window, seen = held
        judged = seen.first(measured, uncertainty) or seen.keep(
            MeasuredAsJudged(window, measured, uncertainty, [evidence()])
        )
        self.judged.append(judged)


class MeasureWaits:
    """:func:`judge_measure_waits` of measurements given one at a time (issue 22, memory27:
    the recorder pass hands each one over once it is over and forgets it): :meth:`take`
    each in the order begun, then :meth:`findings`. What it holds across them is the
    tally (counts, the first labels, the violations) and the R-4.4.5-04 waits
    (:class:`Waits`), never a measurement."""

    def __init__(self, uncertainty: float, stalls: Sequence[Stall] = ()) -> None:
        self.uncertainty = uncertainty
        self.stalls = stalls
        self.tally = Tally(("R-4.4.5-05", "R-4.4.5-06", "R-4.4.5-07"))
        self.tally.decision("R-4.4.5-05", REACTION_DECISION)
        self.early = Waits(
            "R-4.4.5-04", "aD0! (or its break) after the reply, with no service request before it"
        )
        self._after_request: dict[str, Finding] = {}  # each label's PASS, made once

    def take(self, m: ObservedMeasurement) -> None:
        """The next measurement, in the order begun."""
        if m.kind not in SR_KINDS:
            return
        tally = self.tally
        where = escape(m.start.text)
        tally.observe(where, ids=["R-4.4.5-06"])
        for other in m.others:
            tally.fail(
                "R-4.4.5-06",
                where,
                f"{other.at()} went to another sensor before the data of {where} were in",
            )
        first = m.first_data
        if m.ttt == 0:
            tally.observe(where, ids=["R-4.4.5-05"])
            if first is None:
                tally.fail("R-4.4.5-05", where, "ttt = 000 but no aD0! followed", warning=True)
            elif first.start - m.reply_end > REACTION:
                tally.fail(
                    "R-4.4.5-05",
                    where,
                    beyond_reaction(first.start - m.reply_end, "ttt = 000"),
                    warning=True,
                )
            return
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
            _no_data_command(tally, m, where, ready, self.uncertainty, self.stalls)
            return
        if sr is None or sr > first.start:
            self.early.judge(
                first.start - m.reply_end,
                self.uncertainty,
                m.ttt,
                lambda: f"{first.at()} after {where} announced ttt={m.ttt}",
            )
        else:
            passed = self._after_request.get(where)
            if passed is None:
                passed = self._after_request[where] = Finding(
                    "R-4.4.5-04",
                    Verdict.PASS,
                    f"aD0! only after the service request ({where})",
                    observed=1,
                )
            self.early.judged.append(passed)
        _judge_reaction(tally, m, first, where, sr, ready)

    def findings(self) -> list[Finding]:
        """R-4.4.5-04..07 over every measurement taken."""
        ok = {"R-4.4.5-05": f"aD0! within {REACTION} s of the service request or ttt (decision T1)"}
        early = combine("R-4.4.5-04", self.early.judged, "wait for data")
        return [early, *self.tally.findings(ok)]


def _judge_reaction(
    tally: Tally,
    m: ObservedMeasurement,
    first: Transmission,
    where: str,
    sr: float | None,
    ready: float,
) -> None:
    """R-4.4.5-05 for a measurement with ttt > 0 and a data command after it: that command is
    aD0! (:func:`_not_d0`), within the reaction allowance of the service request or ttt,
    and after a break when ttt ran out."""
    tally.observe(where, ids=["R-4.4.5-05"])
    if _not_d0(first):
        tally.fail(
            "R-4.4.5-05",
            where,
            f"the first data command after the measurement was {escape(first.stem)}, not aD0!",
        )
    trigger = sr if sr is not None and sr <= ready else ready
    delay = first.start - trigger
    if delay > REACTION:
        what = "the service request" if trigger == sr else "ttt"
        tally.fail("R-4.4.5-05", where, beyond_reaction(delay, what), warning=True)
    if trigger != sr and first.break_event is None:
        tally.fail("R-4.4.5-05", where, "aD0! after ttt ran out, without a break first")


def judge_concurrent_waits(
    taken: Sequence[ObservedMeasurement], uncertainty: float
) -> list[Finding]:
    """R-4.4.7-06: after a concurrent reply with ttt > 0, no data command to that sensor before
    ttt (talking to other sensors meanwhile is allowed). One :class:`ConcurrentWaits` given
    each of ``taken`` in order."""
    waits = ConcurrentWaits(uncertainty)
    for m in taken:
        waits.take(m)
    return waits.findings()


class ConcurrentWaits:
    """:func:`judge_concurrent_waits` of measurements given one at a time (as
    :class:`MeasureWaits`): what it holds is the waits (:class:`Waits`)."""

    def __init__(self, uncertainty: float) -> None:
        self.uncertainty = uncertainty
        what = "first data command (or its break) after the concurrent reply"
        self.waits = Waits("R-4.4.7-06", what)

    def take(self, m: ObservedMeasurement) -> None:
        """The next measurement, in the order begun."""
        first = m.first_data
        if m.kind not in CONCURRENT_KINDS or not m.ttt or first is None:
            return
        self.waits.judge(
            first.start - m.reply_end,
            self.uncertainty,
            m.ttt,
            lambda: f"{first.at()} after {escape(m.start.text)} (ttt={m.ttt})",
        )

    def findings(self) -> list[Finding]:
        """R-4.4.7-06 over every measurement taken."""
        return [combine("R-4.4.7-06", self.waits.judged, "concurrent wait")]


def _no_data_command(
    tally: Tally,
    m: ObservedMeasurement,
    where: str,
    ready: float,
    uncertainty: float,
    stalls: Sequence[Stall] = (),
) -> None:
    """R-4.4.5-05 for a measurement after which no aD0! came: a FAIL when the recorder moved on
    or ended its job; undecided, naming the stall, when it sent the same command again
    (nothing else between) across a noted stall of the tool's host (:func:`.stalls.tried_again`).
    When the tool cut the job at its budget with the recorder still in this
    measurement: a FAIL when the cut came past the allowance after the service request or ttt
    (no aD0! at all where one was due: not a late one, which decision T1 makes a WARN);
    undecided when it came before an aD0! was due, which says nothing."""
    if m.cut_at is None:
        stall = tried_again(m, stalls)
        if stall is not None:
            tally.undecide(
                "R-4.4.5-05",
                where,
                f"no aD0! after the measurement (its command sent again), but {stall.why()}",
            )
            return
        tally.fail("R-4.4.5-05", where, "no aD0! after the measurement")
        return
    sr = m.service_request_end
    trigger = sr if sr is not None and sr <= ready else ready
    what = "the service request" if trigger == sr else "ttt ran out"
    waited = m.cut_at - trigger
    if waited - uncertainty > REACTION:
        tally.fail(
            "R-4.4.5-05",
            where,
            f"no aD0! in the {waited:.3f} s from when {what} to the tool cutting the job at "
            "its budget",
        )
    else:
        tally.undecide(
            "R-4.4.5-05",
            where,
            f"the tool cut the job at its budget {waited:.3f} s after {what}, before an "
            f"aD0! was due (within {REACTION} s, decision {REACTION_DECISION})",
        )


def _not_d0(first: Transmission) -> bool:
    """The measurement's first data command asks for a later index than 0: no aD0! was
    issued (an STM32 HAL logger whose aD0! went out on the other pin, HarveyBates/
    stm32-projects: its aD1! PASSed R-4.4.5-05 "aD0! within 0.5 s of ... ttt")."""
    d = first.data_index
    return d is not None and d[1] != 0
