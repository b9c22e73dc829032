"""The recorder rules whose findings stand where the served line's lateness is its stalls'
(truth32).

A stall of the tool's process (a loaded host, a paused process) moves what the served line
or a listening link stamped around it, and on a served line it holds up the played sensors
and an in-process recorder with it: a gap inside a command, a break's length or the marking
before a command that spans one is the host's doing as much as the recorder's. The judges
of the recorder's own timing read the noted stalls (:attr:`~conformance.view.segments.
TranscriptView.stalls`) and hold a deviation whose decisive interval one covers, naming it
(:func:`~conformance.judges.stalled.stalled_interval`, :func:`~conformance.judges.stalled.
held_by`); outside every stall they judge as before. What they measure is the recorder's
own doing alone, so where every late frame of a served run fell inside a noted stall the
served line's whole-run guard (``ConformanceRun._guard_served_line``) leaves their findings
as judged.

The retry judges (R-7.2-02, -06) hold what a noted stall covers too, but stay under the
guard: a retry answers the played sensor's replies, and a stall's disorder outlives its
window there (truth32's reproduction: a reply held back 135 ms met the in-process
recorder's retry, and the sensor's next reply, 115 ms after the stall's note, began late
enough that the recorder broke into it; R-7.2-06 FAILed on it). R-7.2-01, -03, -04 and -05
read that disorder (truth34: from the sensor's standby before a try, or the reply it met
still coming, to the standby after what the try heard) and stand as judged.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, TypeVar

from ...links.host_stall import REACH, Stall, stalled_over
from ...transcript import Event
from ...verdicts import Finding, Verdict
from ..cite import STAMP
from ..stalled import stalled_interval
from ..tally import Tally
from ..timing import Measured
from .common import REACTION

if TYPE_CHECKING:
    from .measurements import ObservedMeasurement

J = TypeVar("J", Finding, Measured)
_DEVIATING = (Verdict.FAIL, Verdict.WARN)

#: the rules whose judges read the stalls and measure the recorder's own timing alone
READ_STALLS = frozenset(
    {
        "R-7.0-01",  # commands.CharacterGaps: a gap in the tolerance band across a stall
        "R-7.0-13",  # commands.CharacterGaps: a gap inside a command across a stall
        "R-4.4-04",  # commands.CommandText: a command's part 'dropped' at a gap across one
        "R-7.0-02",  # breaks.Breaks: a break's length
        "R-7.0-06",  # breaks.Breaks: the marking after a break
        "R-7.0-17",  # breaks.BreakRules: the marking before a command sent without a break
        "R-7.1-01",  # breaks.BreakRules: aD0! without a break after the service request
        # truth34: the retry rules whose judges read a stall's disorder past its span (the
        # sensor's standby before a try, a reply held back still coming, the standby after
        # what a try heard: retries._unsettled_from, _decided_by)
        "R-7.2-01",  # retries: "not sent again", "only after a new break"
        "R-7.2-03",  # retries: "n retries, then no more"
        "R-7.2-04",  # retries: "gave up after n sequences"
        "R-7.2-05",  # retries: "then a new sequence" / "then no retry"
        "R-4.4.14-01",  # capabilities.judge_transparent: the break, the reply relayed
    }
)


def hold(
    stalls: Sequence[Stall],
    judged: J,
    start: float,
    end: float,
    high: float | None = None,
) -> J | Finding:
    """``judged`` (a finding on the line between ``start`` and ``end``), or where it FAILs
    or WARNs across noted stalls of the tool's own host that can account for it, the same
    INCONCLUSIVE naming the first (:func:`~conformance.judges.stalled.stalled_interval`).

    A stall compresses what it held back into one late read (a break, a marking, a gap
    read shorter, down to nothing), so any deviation of that kind across one is held. It
    stretches an interval (a paused in-process recorder, a reply it held back) by at most
    its own length: an interval over ``high`` (s) by more than the stalls over it may have
    added (each its measured length and :data:`~conformance.links.host_stall.REACH`),
    beyond its uncertainty, still FAILs (a recorder that sends aD0! without a break 2 s
    after ttt is not excused by the 150 ms stall inside those 2 s)."""
    if not stalls or judged.verdict not in _DEVIATING:
        return judged
    over = [stall for stall in stalls if stall.overlaps(start, end)]
    if not over:
        return judged
    if high is not None:
        measured, uncertainty = _figures(judged)
        if measured is not None and measured > high:
            added = sum(stall.ms / 1e3 + REACH for stall in over)
            if measured - added - uncertainty > high:
                return judged
    return stalled_interval(judged, over[0])


def _figures(judged: Finding | Measured) -> tuple[float | None, float]:
    """The measured interval and its uncertainty (s) of ``judged``."""
    if isinstance(judged, Measured):
        return judged.measured, judged.uncertainty
    if judged.measured_ms is None:
        return None, 0.0
    return judged.measured_ms / 1e3, (judged.uncertainty_ms or 0.0) / 1e3


def tried_again(m: ObservedMeasurement, stalls: Sequence[Stall]) -> Stall | None:
    """The first noted stall over ``m``'s command and its reply, where the recorder sent that
    command again next (nothing between; a new try: it took the reply for missing) within
    :data:`~.common.REACTION` of the stall's end; None otherwise (truth33). truth32's paused
    clean runs: the played sensor's reply went out 150 ms late, or the in-process recorder
    was paused as it came, and the recorder tried again 0-230 ms after it; "no aD0!"
    (R-4.4.5-05) and "0 of 3 values" (R-4.4.8-05) were the host's doing. A recorder that
    turns to anything else after the reply, or sends the command again long after the
    stall, is not excused."""
    again = m.next_start
    if not stalls or again is None or m.others or again.text != m.start.text:
        return None
    stall = stalled_over(stalls, m.start.start, m.reply_end)
    if stall is None or again.start > stall.end + REACTION:
        return None
    return stall


def over_collection(m: ObservedMeasurement, stalls: Sequence[Stall]) -> Stall | None:
    """The first noted stall over ``m``'s data exchanges, from its first data command to the
    end of what its last one heard, None where none is (truth33): a reply held back meets
    the recorder's retry and what the view reads of it is garbled (truth32's paused clean
    run: 0M2!'s D1 and D2 replies collided with retries, "stopped after 0D2! with 6 of 9
    values" though the recorder logged all 9), so the values counted are not the recorder's."""
    if not stalls or not m.data:
        return None
    last = m.data[-1][0]
    end = last.heard[-1].end if last.heard else last.end
    return stalled_over(stalls, m.data[0][0].start, end)


def fail_unless_stalled(
    tally: Tally,
    stalls: Sequence[Stall],
    rid: str,
    where: str,
    message: str,
    span: tuple[float, float],
    *,
    warning: bool = False,
) -> None:
    """``tally.fail`` of ``rid`` at ``where``, or where a noted stall of the tool's host
    overlaps ``span`` (s, s: the stretch of line the deviation rests on, from the first
    moment a stall could have disturbed it to the recorder's decision), the same observation
    left undecided naming the stall (truth34): a tallied rule's counterpart of :func:`hold`.
    A rule whose judges tally needs it for each observation, not for the combined finding:
    one deviation outside every stall still FAILs it."""
    stall = stalled_over(stalls, *span) if stalls else None
    if stall is None:
        tally.fail(rid, where, message, warning=warning)
    else:
        tally.undecide(rid, where, f"{message}, but {stall.why()}")


#: the start of the title a recorder case gives each scenario slice it judged
SCENARIO_TITLE = "scenario "


def late_near(evidence: Iterable[tuple[str, Sequence[Event]]], stalls: Sequence[Stall]) -> bool:
    """Whether what a case judged may have been disturbed by the served line's noted
    lateness (truth34: the line notes every frame it sent late, so the notes are all of
    it): a noted stall lies over one of the scenario slices in its ``evidence``, or within
    :data:`~.common.REACTION` before one (its disorder outlives its span: a reply held
    back, a sensor asleep by its own clock). A case that names no scenario slice judged
    what it cannot show here: True, held as the whole run was before."""
    spans = [
        (events[0].start, max(e.end for e in events))
        for title, events in evidence
        if title.startswith(SCENARIO_TITLE) and events
    ]
    if not spans:
        return True
    return any(stalled_over(stalls, start - REACTION, end) for start, end in spans)


#: how far (s) from every noted stall a deviation of an in-process recorder must lie for the
#: served line's guard to let a rule whose judge reads the stalls stand: the host holds up
#: its threads around a stall too, where nothing notes it (base-s69's paused clean run: a
#: 1.15 ms break 184 ms after a note)
NEAR = 1.0


def stamped_far(finding: Finding, stalls: Sequence[Stall]) -> bool:
    """Whether every place ``finding`` names (its ``t=... s`` stamps, in its detail and
    evidence) lies more than :data:`NEAR` from every noted stall; False where it names none
    (truth34: no-break-after-87ms' "2005.70 ms before 0D0! at t=43.521 s", 38 s from the
    run's one note, stands; a deviation beside a stall does not)."""
    texts = (finding.detail, *finding.evidence)
    times = [float(t) for text in texts for t in STAMP.findall(text)]
    return bool(times) and all(stalled_over(stalls, t - NEAR, t + NEAR) is None for t in times)
