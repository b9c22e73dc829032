"""Sensor-role judges over the whole transcript: response timing, character gaps, framing of
every reply, the sensors' bit rate.

They read the shared view (:mod:`conformance.view`): each transmission of the recorder, cut
for timing evidence into the sensor's reply (the run of characters that starts soon after the
command) and anything it sent later before the recorder spoke again (service requests,
chatter) (:class:`~conformance.view.runs.Segment`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Iterator
from dataclasses import replace
from itertools import repeat
from math import copysign, isnan
from operator import attrgetter, sub

from ..links.host_stall import Stall, stalled_over
from ..protocol.commands import ADDRESS_CHARS, MEASUREMENT_KINDS, CommandError, parse_command
from ..protocol.framing import ETX, STX
from ..protocol.responses import split_line
from ..protocol.timing import (
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    NO_BREAK_WINDOW,
    RESPONSE_START_MAX,
    RESPONSE_START_MIN,
    TOLERANCE,
)
from ..tool_recorder.validity import fits_shape
from ..transcript import GOOD_PARITY, SEVEN_BITS, Event, escape, text7, wire_bytes
from ..verdicts import Finding, Verdict
from ..view.runs import Segment, Segments, frames, runs, segments
from ..view.sides import expected_reply_address
from .continued_talk import segment_continues
from .stalled import stalled_interval, through_stall
from .tally import Tally
from .timing import (
    Measured,
    Observation,
    Observed,
    Place,
    Repeats,
    StampUncertainty,
    Window,
    combine_local,
    judge_window,
    stamp_uncertainty,
    sustained,
    to_confirm,
)

_START = attrgetter("start")
#: what an interval read across a host stall is held for (a violation it shows is the
#: stall's); one the stamps' uncertainty leaves undecided is undecided as ever
_DEVIATING = (Verdict.FAIL, Verdict.WARN)
_END = attrgetter("end")

# The cut these judges read lives in the shared view; re-exported for the timing diagram
# (reports/) and the sensor measurement judges, which import it from here.
__all__ = [
    "ReplyGaps",
    "ResponseStarts",
    "Segment",
    "gaps_to_confirm",
    "judge_framing",
    "judge_gaps",
    "judge_reply_bit_rate",
    "judge_response_start",
    "reply_char_pairs",
    "reply_gaps",
    "runs",
    "segments",
    "starts_after_a_retry",
    "starts_to_confirm",
]


# -- timing ---------------------------------------------------------------------------------
def judge_response_start(
    segs: list[Segment], uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
) -> list[Finding]:
    """R-7.0-09 (not before 7.93 ms) and R-7.0-10 (within 15.40 ms) for every reply, each
    with the uncertainty of the stamps it rests on (the command's last, the reply's first).
    ``stalls``: the tool's own host stalls the link noted (:func:`~conformance.links.
    host_stall.stalls`): a reply start that deviates across one is set aside, the stall
    named (:func:`~.stalled.stalled_interval`, truth29)."""
    stamps = stamp_uncertainty(uncertainty)
    early, late = _starts(segs, stamps, stalls)
    real = stamps.local is not None
    return [
        combine_local("R-7.0-09", early, "reply", real_time=real),
        combine_local("R-7.0-10", late, "reply", real_time=real),
    ]


def starts_to_confirm(
    segs: list[Segment], uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
) -> list[str]:
    """The commands whose replies :func:`judge_response_start` wants observed again: rare
    deviations on a real-time link not yet placed (:func:`~.timing.to_confirm`)."""
    stamps = stamp_uncertainty(uncertainty)
    if stamps.local is None:  # a virtual clock: nothing to confirm (to_confirm)
        return []
    early, late = _starts(segs, stamps, stalls)
    both = to_confirm(early, real_time=True) + to_confirm(late, real_time=True)
    return list(dict.fromkeys(both))


def starts_after_a_retry(
    segs: list[Segment], uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
) -> bool:
    """Whether R-7.0-10 is left with no reply to judge because every reply it might time
    began after a retry, read in time from the retry and late from the unanswered try before
    it (:func:`_unanswered_before`): a sensor plainly late (the Arduino Due sensor's delay(80)
    before every reply, docs/kit.md eighteenth round) is then INCONCLUSIVE. The case sends
    one command once, with no retry, to time a reply from that command alone
    (:meth:`~conformance.sensor.session.SensorSession.late_start_probe`); a run with any
    reply R-7.0-10 times (every clean run) sends nothing more."""
    stamps = stamp_uncertainty(uncertainty)
    _, late = _starts(segs, stamps, stalls)
    if late:
        return False
    before: Segment | None = None
    for seg in segs:
        earlier = _unanswered_before(before, seg)
        before = _carried(earlier, seg)
        if earlier is None or _reply_set_aside(seg) or _not_a_reply_to(seg):
            continue
        start = seg.reply[0].start
        if LATE_WINDOW.inside(start - seg.command_end) != LATE_WINDOW.inside(
            start - earlier.command_end
        ):
            return True
    return False


#: R-7.0-09 and R-7.0-10, against which every reply's start is judged
EARLY_WINDOW = Window(
    "R-7.0-09", "first response start bit after the command", low=CHAR_TIME, tolerance=TOLERANCE
)
LATE_WINDOW = Window(
    "R-7.0-10", "first response start bit after the command", high=RESPONSE_START_MAX
)


def _starts(
    segs: list[Segment], stamps: StampUncertainty, stalls: list[Stall] | None = None
) -> tuple[list[Observation], list[Observation]]:
    """R-7.0-09's and R-7.0-10's observations of a whole run's ``segs``, once per
    :class:`Segments` and stamps: test_response_start_window asks
    :func:`starts_after_a_retry` and then :func:`judge_response_start` of the same segments
    (a real link's :func:`starts_to_confirm` before both), and each walked every reply of
    the run again (issue 22: some 1,500 replies a fault-matrix row, twice). Nobody changes
    the lists: the judges read them."""
    if isinstance(segs, Segments):
        return segs.derived(
            "_wire_starts",
            (stamps, tuple(stalls or ())),
            lambda: _start_observations(segs, stamps, stalls=stalls)[:2],
        )
    return _start_observations(segs, stamps, stalls=stalls)[:2]


def _start_observations(
    segs: list[Segment],
    stamps: StampUncertainty,
    before: Segment | None = None,
    stalls: list[Stall] | None = None,
) -> tuple[list[Observation], list[Observation], Segment | None]:
    """R-7.0-09's and R-7.0-10's observations of ``segs``, and the last segment (which
    ``before`` carries into the next window's: its reply may be late, after the cut). A
    start that deviates where one of ``stalls`` (the tool's host's) may have moved its
    stamps, from the command's last character to the reply's first, is that stall's
    (:func:`_across_stall`)."""
    early: list[Observation] = []
    late: list[Observation] = []
    texts = _texts(segs)
    for k, seg in enumerate(segs):
        prev = before
        earlier = _unanswered_before(before, seg)
        before = _carried(earlier, seg)
        if not seg.reply or _reply_set_aside(seg) or _not_a_reply_to(seg):
            continue
        if (seg.contention or (prev is not None and prev.contention)) and segment_continues(
            prev, seg
        ):
            continue  # the next line of a talk set aside: no reply to this command
        delay = seg.reply[0].start - seg.command_end
        u = stamps.between(seg.command[-1].start, seg.reply[0].end)
        tainted = u > stamps.base
        # the evidence line is made when a finding shows this reply (_StartWhere), not for
        # each of the run's ~900 replies (issue 22, matrix23)
        where = _StartWhere(seg, earlier)
        place: Place = (seg.text, _text(seg) if texts is None else texts[k], 0)
        spacing = _spacing_before_reply(seg)
        for window, out in ((EARLY_WINDOW, early), (LATE_WINDOW, late)):
            measured, said = delay, where
            if window is EARLY_WINDOW and spacing is not None:
                # the sensor drove the line spacing first: R-7.0-09's marking ended there
                measured = max(spacing.start, seg.command_end) - seg.command_end
                said = [
                    f"{where()[0]}: the sensor held the line spacing from "
                    f"{measured * 1e3:.2f} ms after the command, {spacing.duration * 1e3:.2f} "
                    f"ms (a break), before its reply at {delay * 1e3:.2f} ms"
                ]
            if earlier is not None:
                other = measured + seg.command_end - earlier.command_end
                if window.inside(measured) != window.inside(other):
                    continue
            judged = Measured(window, measured, u, said)
            if stalls and judged.verdict in _DEVIATING:
                span = (seg.command[-1].start, seg.reply[0].end)
                if (held := _across_stall(judged, stalls, *span, place)) is not None:
                    out.append(held)
                    continue
            out.append((judged, tainted, place))
    return early, late, before


def _across_stall(
    judged: Measured, stalls: list[Stall], start: float, end: float, place: Place
) -> Observation | None:
    """The observation of a deviating interval (a FAIL or WARN) whose stamps,
    ``start``..``end``, one of ``stalls`` may have moved (a character the host held back is
    stamped at the burst that delivers it): INCONCLUSIVE naming the stall, tainted by it,
    so :func:`~.timing.combine_local` sets it aside and asks for its place again (truth29).
    None: outside every stall, judged as ever. (One the stamps' uncertainty leaves
    undecided is not held: a clean run under 80-200 ms pauses re-probed some 40 commands
    for those, and its R-7.0-09 came out INCONCLUSIVE where base-s66 PASSed.)"""
    stall = stalled_over(stalls, start, end)
    return None if stall is None else (stalled_interval(judged, stall), stall, place)


class _StartWhere:
    """The evidence line of a reply's start (:func:`_start_observations`), made when first
    asked (the finding of a FAIL or WARN at once, else of the few a verdict shows) and then
    the same list; the reply may answer the unanswered command ``earlier`` before it, late
    (:func:`_unanswered_before`): it counts only where both readings give the same answer.
    Holds the few values the line reads, not the segments: a recording read a window at a
    time (:class:`ResponseStarts`) kept every reply's segment, its events as objects, to the
    end of the run (issue 22, memory19: 35,000 events of a sensor, 5 MB, at an hour)."""

    __slots__ = ("at", "earlier", "lines", "text")

    def __init__(self, seg: Segment, earlier: Segment | None) -> None:
        self.text, self.at = seg.text, seg.command_end
        #: the unanswered command's text and how long after it the reply began
        self.earlier = (
            None if earlier is None else (earlier.text, seg.reply[0].start - earlier.command_end)
        )
        self.lines: list[str] | None = None

    def __call__(self) -> list[str]:
        if self.lines is None:
            line = f"reply to {escape(self.text)} at t={self.at:.4f} s"
            if self.earlier is not None:
                text, lagged = self.earlier
                line = (
                    f"{line} (or to {escape(text)} before it, {lagged * 1e3:.2f} ms after that one)"
                )
            self.lines = [line]
        return self.lines


def _spacing_before_reply(seg: Segment) -> Event | None:
    """The sensor's first break (:attr:`Segment.sensor_breaks`) on the line after the command
    ended and begun before its reply's first character: the first spacing the sensor put on the
    line, where its 8.33 ms of marking (R-7.0-09) ended, whatever its reply's first start
    bit says. The twenty-fourth round's sketch "wakes the sensors" (12.1 ms of spacing)
    0.00 ms after every command, then marks 8.4 ms and replies 20.06 ms after it: R-7.0-09
    PASSed on the 20.06 ms, though a UART would read a start bit at 0.00 ms."""
    breaks = seg.sensor_breaks
    if not breaks:  # nearly always: no generator made for none
        return None
    first = seg.reply[0].start
    end = seg.command_end
    return next((b for b in breaks if b.end > end and b.start < first), None)


def _unanswered_before(before: Segment | None, seg: Segment) -> Segment | None:
    """The command before ``seg`` if ``seg``'s reply may be that command's late reply: it got
    no reply and nothing after it, and the reply starts with the address its reply would
    (any for ``?!`` and ``aAb!``). Found on an Arduino Due sensor (eighteenth round, docs/
    kit.md) whose every reply starts 100 ms after its command: the tool's retry 55 ms after
    the first try had ended before the reply began, and the reply was timed from the retry,
    11.35 ms, an in-time reply (R-7.0-10 PASS evidence), 16 such; '$<CR><LF>' answering
    ``0A$!`` was timed as a reply to the ``0!`` sent after it (53.01 ms). The wire cannot
    tell which command a reply that began after both answers."""
    if before is None or before.reply or before.later or before.contention:
        return None
    if not before.text or not seg.reply:
        return None
    address = expected_reply_address(before.text)
    if address is not None and seg.reply[0].char7 != ord(address[0]):
        return None
    return before


def _carried(earlier: Segment | None, seg: Segment) -> Segment:
    """What the next segment's :func:`_unanswered_before` reads as the command before it:
    ``seg``, or, where ``seg``'s reply may be ``earlier``'s late reply and names another
    address than ``seg``'s command asks (so it is not ``seg``'s), ``seg`` as unanswered: the
    reply after the next command may be ``seg``'s own, late. Seed 7900 (accepts-invalid-
    address + answers-foreign-address + replies-after-retry): '$<CR><LF>' answering
    ``0A$!`` 80 ms late came 33 ms into the ``0!`` after it, and that ``0!``'s '0<CR><LF>',
    held behind it, began as the next ``0!`` ended: R-7.0-09 FAILed "0.00 ms" (truth36)."""
    if earlier is None or not seg.reply:
        return seg
    address = expected_reply_address(seg.text)
    if address is None or seg.reply[0].char7 == ord(address[0]):
        return seg
    return replace(seg, reply=[])


def _reply_set_aside(seg: Segment) -> bool:
    """Whether characters stamped after the command ended were set aside as contention
    (two talkers between its echoes): they may be the reply's own start, so what is left is
    not surely its first. eff12, on a link that echoes and batches (``--echo --usb-latency
    16``): a reply '0<CR><LF>' set aside left the stray '#' a sensor sent after its LF timed
    as the reply, 39.83 ms, a false R-7.0-10 FAIL. A character that started before the
    command ended (a service request that met it) is no reply: the one after it is timed."""
    met = seg.contention
    if not met:  # nearly always: no generator made for none
        return False
    end = seg.command_end
    return any(e.start >= end for e in met)


def _not_a_reply_to(seg: Segment) -> bool:
    """Whether what follows the command is no reply to it, so its start says nothing of how
    soon the sensor answers: a run the sensor had under way when the command ended (its
    first character follows, within a character gap, one that started before the end), or
    one that names another address than the command's sooner than any reply may start
    (R-7.0-09's 7.93 ms): an answer to something sent before, which cannot have been begun
    for this command. The sixteenth outside round's sketch answered the two ?! it had kept
    through its boot 1.50 ms after the tool's first 0!, '5<CR><LF>' from a sensor at '5':
    R-7.0-09/-10 counted "1.50..7.67 ms" over it (docs/kit.md)."""
    first = seg.reply[0]
    end = seg.command_end
    met = seg.contention
    under_way = bool(met) and any(  # nothing met the command, nearly always: no generator
        e.start < end and first.start - e.end <= INTER_CHAR_GAP_MAX + TOLERANCE for e in met
    )
    if under_way:
        return True
    address = expected_reply_address(seg.text)
    named = chr(first.char7)
    return (
        address is not None
        and named != address
        and named in ADDRESS_CHARS
        and first.start - end < RESPONSE_START_MIN
    ) or _request_not_reply(seg, address)


def _request_not_reply(seg: Segment, address: str | None) -> bool:
    """Whether what follows the command is a service request's bare words ``a<CR><LF>``,
    begun sooner than any reply may (R-7.0-09's 7.93 ms), that are no reply to it: not
    shaped as its reply, or followed by a line that is. A sensor sends its request when it
    is ready; one due while the tool's command was on the line follows it at once, and a
    request is no response, whose marking R-7.0-09 times. service-request-after-ttt-zero
    beside inter-char-gap: '0<CR><LF>' 0.00 ms after 0D0!, D0's values 8 ms after it;
    beside replies-after-retry: 0.00 ms after 0MC1!'s retry, its '00002' heard over the try
    before: R-7.0-09 FAILed "0.00 ms" on both (truth19). A sensor whose own reply is those
    words (``a!``, an empty D reply) with no reply of the command's shape after them is
    timed as before."""
    reply = seg.reply
    if address is None or len(reply) != 3 or reply[0].start - seg.command_end >= RESPONSE_START_MIN:
        return False
    text = text7(reply)
    if text != address + "\r\n":
        return False
    try:
        command = parse_command(seg.text)
    except CommandError:
        return False
    if not fits_shape(command, text):
        return True
    return any(fits_shape(command, text7(run)) for run in runs(seg.later))


def talked_through(seg: Segment) -> bool:
    """Whether the command talked over multi-line text the sensor had begun: the characters
    that met it (``contention``) start ``a<STX>`` and hold no ETX yet, so what follows the
    command up to the ETX is the rest of that text, a late reply to an earlier try that the
    retry met (the replies-after-retry sensor answered 0XHELP! 80 ms late: its first line met
    the retry and its other lines came after it). Neither its framing nor the gaps between
    its lines are a reply's of this command to judge (truth12: R-4.2-02/-03 and R-4.3-01
    FAILed "later, after 0XHELP!: reply '<ETX>'", R-7.0-12 the 6.67 ms between two of its
    lines, R-4.4.13.1-03's to judge)."""
    met = seg.contention
    return (
        len(met) > 1
        and met[0].start < seg.command_end
        and met[1].char7 == STX
        and all(e.char7 != ETX for e in met)
    )


def _text(seg: Segment) -> str:
    """All the sensor sent after the command, as text: part of an observation's place (one
    C pass over the characters, :func:`~conformance.transcript.text7`)."""
    return text7(seg.reply + seg.later)


def _texts(segs: list[Segment]) -> list[str] | None:
    """Each segment's :func:`_text` ('' where the sensor sent nothing), made once per
    :class:`Segments`: R-7.0-09/-10's places and R-7.0-12's read the same text of every
    reply of a run, and each made it again (issue 22, matrix23). None for a plain list (a
    window of a recording): its callers make each text as they go."""
    if not isinstance(segs, Segments):
        return None
    return segs.derived(
        "_wire_texts", None, lambda: [_text(s) if s.reply or s.later else "" for s in segs]
    )


def reply_gaps(segs: list[Segment]) -> list[tuple[float, str]]:
    """Every marking gap between consecutive characters of one DUT run, with its context."""
    return [(gap, where) for gap, where, _a, _b, _p in _gaps(segs)]


def reply_char_pairs(segs: list[Segment]) -> list[tuple[Event, Event]]:
    """The consecutive character pairs :func:`judge_gaps` measures a gap between."""
    return [(a, b) for _gap, _where, a, b, _p in _gaps(segs)]


Gap = tuple[float, str, Event, Event, Place]


def _gaps(segs: list[Segment]) -> list[Gap]:
    """Each gap with its place (:func:`_cut_gaps`), cut once per :class:`Segments`."""
    if isinstance(segs, Segments):
        return segs.derived("_wire_gaps", None, lambda: _cut_gaps(segs))
    return _cut_gaps(segs)


def _cut_gaps(segs: list[Segment]) -> list[Gap]:
    """Each gap with its place: the command and the index of the character after the gap
    among everything the sensor sent after it (where a device's own gap recurs)."""
    gaps: list[Gap] = []
    for seg, where, text, multiline in _placed(segs):
        for first, run in _placed_runs(seg):
            gaps += _run_gaps(run, first, where, (seg.text, text), multiline)
    return gaps


def _placed(segs: list[Segment]) -> Iterator[tuple[Segment, str, str, bool]]:
    """Each segment the sensor sent anything in, with what places its gaps: the evidence
    line, all it sent after the command as text, and whether the pauses after its LFs are
    between lines of multi-line text (R-4.4.13.1-03's 150 ms, not a gap), which is so too
    for the rest of multi-line text the command talked over."""
    texts = _texts(segs)
    for k, seg in enumerate(segs):
        if seg.reply or seg.later:
            multiline = seg.multiline or talked_through(seg)
            text = _text(seg) if texts is None else texts[k]
            yield seg, f"in reply to {escape(seg.text)}", text, multiline


def _placed_runs(seg: Segment) -> Iterator[tuple[int, list[Event]]]:
    """The segment's runs of characters (the whole reply, however long a gap inside it: a
    gap is R-7.0-12's evidence; then each run of what came later), each with the index of
    its first character in all the sensor sent after the command."""
    first = 0
    for run in [seg.reply, *runs(seg.later)]:
        yield first, run
        first += len(run)


def _run_gaps(
    run: list[Event], first: int, where: str, reply: tuple[str, str], multiline: bool
) -> list[Gap]:
    """The gaps between consecutive characters of one run (:func:`_placed_runs`), one by
    one, each placed at the index of the character after it."""
    gaps: list[Gap] = []
    add = gaps.append
    k = first
    a = None
    for b in run:
        if a is not None and not (multiline and a.char7 == 0x0A):
            add((b.start - a.end, where, a, b, (*reply, k)))
        a = b
        k += 1
    return gaps


#: How many segments :func:`judge_gaps` cuts the gaps of at once from a plain list: a few
#: hundred gaps held at a time, not the whole recording's.
SEGMENTS_AT_ONCE = 64


def judge_gaps(
    segs: list[Segment], uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
) -> list[Finding]:
    """R-7.0-12: at most 1.66 ms of marking between characters (no tolerance), and R-7.0-01:
    a gap inside the ±0.40 ms band above 1.66 ms uses a tolerance the rule does not grant.
    Each gap carries the uncertainty of the two stamps it rests on.

    A recording's segments (a plain list: the passive runs) are judged
    :data:`SEGMENTS_AT_ONCE` at a time through :class:`ReplyGaps`, the same findings, so
    that no list of every gap is made (an hour of a busy bus: 25,000 a sensor, ~4 MB);
    a run's :class:`~conformance.view.runs.Segments` keep their observations for
    :func:`gaps_to_confirm`, which reads the same, where the stamps have a local
    irregularity (a host-stamped link); on one uncertainty for every gap they are judged
    through :class:`ReplyGaps` too, in one part, each run's gaps at once
    (:meth:`_GapsAlike.add_segments`). ``stalls``: the tool's own host stalls the link
    noted: a gap that deviates across one is set aside, the stall named (truth29)."""
    stamps = stamp_uncertainty(uncertainty)
    if not isinstance(segs, Segments) or (_alike(stamps) and not stalls):
        # on one uncertainty for every gap (a virtual clock, a capture's grid) nothing is
        # confirmed (gaps_to_confirm): a run's segments kept no observations for it either
        # and are judged the same way in one part (issue 22, matrix19)
        gaps = ReplyGaps(stamps, stalls)
        if isinstance(segs, Segments):  # in one part, the Segments themselves (_texts)
            gaps.add(segs)
        else:
            for k in range(0, len(segs), SEGMENTS_AT_ONCE):
                gaps.add(segs[k : k + SEGMENTS_AT_ONCE])
        return gaps.findings()
    gap_finding = combine_local(
        "R-7.0-12",
        _gap_observations(segs, stamps, stalls),
        "character gap",
        real_time=stamps.local is not None,
    )
    tolerance_finding = _judge_tolerance_use(_gaps(segs), stamps.base, stalls)
    return [gap_finding, tolerance_finding]


def gaps_to_confirm(
    segs: list[Segment], uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
) -> list[str]:
    """The commands whose replies :func:`judge_gaps` wants observed again: rare deviating
    gaps on a real-time link not yet placed (:func:`~.timing.to_confirm`)."""
    stamps = stamp_uncertainty(uncertainty)
    if stamps.local is None:  # a virtual clock: nothing to confirm (to_confirm)
        return []
    return to_confirm(_gap_observations(segs, stamps, stalls), real_time=True)


#: R-7.0-12's limit, against which every character gap of a run is judged
GAP_WINDOW = Window(
    "R-7.0-12", "marking between response characters", high=INTER_CHAR_GAP_MAX, tolerance=0.0
)


def _gap_observations(
    segs: list[Segment], stamps: StampUncertainty, stalls: list[Stall] | None = None
) -> list[Observation]:
    """Every gap judged (:data:`GAP_WINDOW`), once per :class:`Segments`, stamps and
    stalls: the rule's judge and its confirmation probe read the same observations."""
    if isinstance(segs, Segments):
        return segs.derived(
            "_wire_gap_observations",
            (stamps, tuple(stalls or ())),
            lambda: _observe_gaps(segs, stamps, stalls),
        )
    return _observe_gaps(segs, stamps, stalls)


def _observe_gaps(
    segs: list[Segment], stamps: StampUncertainty, stalls: list[Stall] | None = None
) -> list[Observation]:
    """Each gap judged against :data:`GAP_WINDOW`. A run's gaps take few distinct values in
    the reply to one command (a simulated sensor's are exact; a real link's stamps are
    quantised), and equal gaps judge alike: each distinct ``(gap, uncertainty, where)`` is
    judged once and its :class:`~.timing.Measured` stands for every gap of that value. A
    gap that deviates across one of ``stalls`` is that stall's (:func:`_across_stall`)."""
    if _alike(stamps) and not stalls:
        return _observe_gaps_alike(_gaps(segs), stamps.base)
    return _observe_each(_gaps(segs), stamps, {}, stalls)


def _alike(stamps: StampUncertainty) -> bool:
    """Whether every gap has the stamps' one uncertainty ``base`` (no local irregularity), a
    plain one (a negative zero is judged apart): the gaps are then judged grouped by value
    (:class:`_GapsAlike`)."""
    base = stamps.base
    return stamps.local is None and not (not base and copysign(1.0, base) < 0)


def _observe_each(
    gaps: list[Gap],
    stamps: StampUncertainty,
    judged: dict[tuple[float, float, str], Measured],
    stalls: list[Stall] | None = None,
) -> list[Observation]:
    """:func:`_observe_gaps`' observations one by one (stamps with a local irregularity, or
    the host stalls ``stalls`` to read them through), ``judged``: the distinct gaps judged
    so far (:class:`ReplyGaps` carries it)."""
    base = stamps.base
    observed: list[Observation] = []
    add = observed.append
    local = stamps.local is not None
    for gap, where, a, b, place in gaps:
        u = stamps.between(a.start, b.end) if local else base
        # -0.0 == 0.0 as a key, but not in a detail text: a negative zero is judged apart
        if (not gap and copysign(1.0, gap) < 0) or (not u and copysign(1.0, u) < 0):
            measured = Measured(GAP_WINDOW, gap, u, [where])
        else:
            key = (gap, u, where)
            measured = judged.get(key)
            if measured is None:
                measured = judged[key] = Measured(GAP_WINDOW, gap, u, [where])
        held = None
        if stalls and measured.verdict in _DEVIATING:
            held = _across_stall(measured, stalls, a.start, b.end, place)
        if held is not None:
            add(held)
            continue
        add((measured, u > base, place))
    return observed


def _observe_gaps_alike(gaps: list[Gap], base: float) -> Observed:
    """:func:`_observe_gaps` where every gap has the stamps' one uncertainty ``base`` (no
    local irregularity: a virtual clock, a capture's sample grid), which is then no part of
    the key and taints none: the same observations, with less asked per gap, grouped as they
    are made (:class:`~.timing.Observed`: what combine_local reads instead of passing over
    some 20,000 gaps a run five more times)."""
    alike = _GapsAlike(base)
    alike.add(gaps)
    return alike.observed


class _GapsAlike:
    """:func:`_observe_gaps_alike` of gaps given a part at a time (:class:`ReplyGaps`, a
    window at a time): the distinct gaps judged so far carried from part to part.
    ``placed``: whether the observations keep their places and order (:class:`~.timing.
    Observed`); :class:`ReplyGaps` keeps neither, which on one uncertainty for every gap
    and no stalls of the tool's host nobody reads (memory24)."""

    def __init__(self, base: float, placed: bool = True) -> None:
        self.base = base
        #: where -> gap -> its index in distinct: what a ``(gap, where)`` key found, asked
        #: per gap without a key tuple made and hashed (a reply's gaps come together, so
        #: the place's own dict is looked up once per reply, not per gap)
        self.judged: dict[str, dict[float, int]] = {}
        self.observed = Observed(placed)

    def add(self, gaps: list[Gap]) -> None:
        base, judged, observed = self.base, self.judged, self.observed
        distinct, counts = observed.distinct, observed.counts
        observe, new, once = observed.observe, distinct.append, counts.append
        last: str | None = None  # the place of the gap before (its dict is ``here``)
        here: dict[float, int] = {}
        for gap, where, _a, _b, place in gaps:
            if where is not last:
                here = judged.setdefault(where, {})
                last = where
            if not gap and copysign(1.0, gap) < 0:  # judged apart, as _observe_gaps does
                observe(len(distinct), place)
                new(Measured(GAP_WINDOW, gap, base, [where]))
                once(1)
                continue
            i = here.get(gap)
            if i is None:
                i = here[gap] = len(distinct)
                new(Measured(GAP_WINDOW, gap, base, [where]))
                once(1)
            else:
                counts[i] += 1
            observe(i, place)

    def add_segments(self, segs: list[Segment], tolerance: _ToleranceUse) -> None:
        """:meth:`add` of :func:`_cut_gaps`' gaps of ``segs``, and ``tolerance``'s, without
        the gaps listed one tuple each: each run's gaps are taken as one list of values made
        in C, grouped by value (few distinct ones a reply) and observed at once
        (:meth:`~.timing.Observed.observe_run`): the same observations, distinct objects in
        the same order and counts (issue 22, matrix19: R-7.0-12's gaps were ~4% of a
        fault-matrix row, a Python call and a tuple a character). A run whose gaps may hold a
        negative zero (judged apart), a NaN, or pauses between lines of multi-line
        text is taken one gap at a time, as before (a zero gap is no such one: a simulated
        sensor's characters come back to back)."""
        base, judged, observed = self.base, self.judged, self.observed
        distinct, counts = observed.distinct, observed.counts
        taken: list[int] = []  # the picks of the runs taken at once, counted at the end
        for seg, where, text, multiline in _placed(segs):
            reply = (seg.text, text)
            here = judged.setdefault(where, {})
            for first, run in _placed_runs(seg):
                if len(run) < 2:
                    continue
                starts = list(map(_START, run[1:]))
                values = list(map(sub, starts, map(_END, run)))
                total = sum(values)
                # a gap is a negative zero only where its character starts at -0.0
                if multiline or total != total or 0.0 in starts:
                    gaps = _run_gaps(run, first, where, reply, multiline)
                    self.add(gaps)
                    tolerance.add(gaps)
                    continue
                fresh = dict.fromkeys(values)
                if not here.keys() >= fresh.keys():  # new ones, judged where they first come
                    for gap in fresh:
                        if gap not in here:
                            here[gap] = len(distinct)
                            distinct.append(Measured(GAP_WINDOW, gap, base, [where]))
                            counts.append(0)
                picks = list(map(here.__getitem__, values))
                taken += picks
                observed.observe_run(picks, reply, first + 1)
                tolerance.add_values(values, where)
        for i, n in Counter(taken).items():
            counts[i] += n


#: how many of the gaps surely inside R-7.0-01's band its FAIL names (its evidence)
NAMED_LEANING = 5


def _leaning(
    sure: list[tuple[float, str]], count: int, uncertainty: float, such: int | None = None
) -> Finding:
    """R-7.0-01's FAIL: the ``(gap, where)`` surely inside the band (the first
    :data:`NAMED_LEANING` are read; ``such``: how many there are, ``len(sure)`` if None),
    out of ``count``."""
    gap, _where = sure[0]
    such = len(sure) if such is None else such
    return Finding(
        "R-7.0-01",
        Verdict.FAIL,
        f"gap of {gap * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} relies on the ±0.40 ms "
        f"tolerance, which the 1.66 ms character gap does not have ({such} such "
        "gap(s))",
        evidence=[where for _, where in sure[:NAMED_LEANING]],
        observed=count,
        measured_ms=round(gap * 1e3, 3),
        limit_ms=INTER_CHAR_GAP_MAX * 1e3,
        uncertainty_ms=round(uncertainty * 1e3, 3),
    )


def _judge_tolerance_use(
    gaps: list[Gap], uncertainty: float, stalls: list[Stall] | None = None
) -> Finding:
    """R-7.0-01 for the one limit without tolerance: a gap surely inside (1.66, 2.06] ms leans
    on a ±0.40 ms the rule does not grant (FAIL); one that only might be there, given the
    link's uncertainty, is INCONCLUSIVE; a gap surely beyond 2.06 ms is R-7.0-12's alone.
    One pass over the gaps (:func:`_gaps`: tens of thousands a run), nearly all below the
    band, where neither test can hold. A gap across one of ``stalls`` (the tool's own host
    stalled: the characters it held back are stamped at the burst that delivers them, so
    the gap before them is the host's) is held, not judged (truth30)."""
    use = _ToleranceUse(uncertainty, stalls)
    use.add(gaps)
    return use.finding()


class _ToleranceUse:
    """:func:`_judge_tolerance_use` of gaps given a part at a time (:class:`ReplyGaps`):
    the gaps in or maybe in the band, and how many gaps, carried from part to part. Of
    those in the band only the few the finding names are kept (the first
    :data:`NAMED_LEANING` surely in it, the first maybe in it, the first held across a
    stall) and how many there are: a bus whose device leans on the tolerance at every
    reply held a tuple a gap to the end (memory24)."""

    def __init__(self, uncertainty: float, stalls: list[Stall] | None = None) -> None:
        self.uncertainty = uncertainty
        self.stalls = stalls
        self.sure: list[tuple[float, str]] = []
        self.maybe: list[tuple[float, str]] = []
        self.sure_count = self.maybe_count = 0  # how many, where the lists keep the first
        #: gaps in or maybe in the band across a stall of the tool's host, with the stall
        #: (the first: the finding names it)
        self.held: list[tuple[float, str, Stall]] = []
        self.count = 0

    def add(self, gaps: list[Gap]) -> None:
        if self.stalls:
            gaps = self._unstalled(gaps)
        self._in_band((g, w) for g, w, _a, _b, _p in gaps)
        self.count += len(gaps)

    def _unstalled(self, gaps: list[Gap]) -> list[Gap]:
        """``gaps`` but those surely in the band (the few: most lie well below it; one
        only maybe in it is INCONCLUSIVE anyway, one surely past it R-7.0-12's) across a
        stall of the tool's own host, kept in :attr:`held`; they are still counted."""
        u, stalls = self.uncertainty, self.stalls
        floor, top = INTER_CHAR_GAP_MAX + u, INTER_CHAR_GAP_MAX + TOLERANCE - u
        kept: list[Gap] = []
        for gap in gaps:
            g, w, a, b, _p = gap
            band = floor < g <= top
            stall = stalled_over(stalls, a.start, b.end) if band and stalls else None
            if stall is None:
                kept.append(gap)
            else:
                if not self.held:
                    self.held.append((g, w, stall))
                self.count += 1
        return kept

    def add_values(self, values: list[float], where: str) -> None:
        """:meth:`add` of gaps of these values, all at ``where`` (none a NaN): the run's
        largest tells at once that none is in or near the band, as nearly always."""
        top, uncertainty = max(values), self.uncertainty
        if top + uncertainty > INTER_CHAR_GAP_MAX or top - uncertainty > INTER_CHAR_GAP_MAX:
            self._in_band(zip(values, repeat(where)))
        self.count += len(values)

    def _in_band(self, gaps: Iterable[tuple[float, str]]) -> None:
        """Keeps the ``(gap, where)`` surely and those maybe in the band."""
        uncertainty, sure, maybe = self.uncertainty, self.sure, self.maybe
        band_lo, band_hi = INTER_CHAR_GAP_MAX, INTER_CHAR_GAP_MAX + TOLERANCE
        for g, w in gaps:
            if g + uncertainty <= band_lo and g - uncertainty <= band_lo:
                continue  # below the band either way (nearly every gap)
            if g - uncertainty > band_lo and g + uncertainty <= band_hi:
                self.sure_count += 1
                if len(sure) < NAMED_LEANING:
                    sure.append((g, w))
            if g + uncertainty > band_lo and g - uncertainty <= band_hi:
                self.maybe_count += 1
                if not maybe:
                    maybe.append((g, w))

    def finding(self) -> Finding:
        return _tolerance_finding(
            self.sure,
            self.maybe,
            self.count,
            self.uncertainty,
            self.held,
            such=(self.sure_count, self.maybe_count),
        )


class ResponseStarts:
    """:func:`judge_response_start` over a recording read a window at a time (issue 22's
    windowed judge): each window's segments :meth:`add`-ed in order, the findings those of
    the whole recording's segments (each reply's delay is its own segment's: the windows'
    observations in order are the whole run's; the last segment is carried, since a reply
    after a cut may be the late reply of an unanswered command before it)."""

    def __init__(
        self, uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
    ) -> None:
        self.stamps = stamp_uncertainty(uncertainty)
        self.stalls = stalls  # the tool's host stalls, as judge_response_start reads them
        # a place is read only on a real-time link (a rare deviation decided by where it
        # falls) or where a stall may set one aside: else none is kept
        placed = self.stamps.local is not None or bool(stalls)
        self.early = _FoldedStarts(placed)
        self.late = _FoldedStarts(placed)
        #: the last segment added: an unanswered command whose late reply may open the next
        self.last: Segment | None = None

    def add(self, segs: list[Segment]) -> None:
        """The replies of ``segs`` (the next window's segments)."""
        early, late, self.last = _start_observations(segs, self.stamps, self.last, self.stalls)
        self.early.add(early)
        self.late.add(late)

    def findings(self) -> list[Finding]:
        """R-7.0-09 and R-7.0-10 over everything added."""
        real = self.stamps.local is not None
        return [
            combine_local("R-7.0-09", self.early.observed(), "reply", real_time=real),
            combine_local("R-7.0-10", self.late.observed(), "reply", real_time=real),
        ]


class _FoldedStarts:
    """One window's reply-start observations (:class:`ResponseStarts`), held folded while
    none is tainted: each distinct value's first :class:`Measured` once
    (:class:`~.timing.Repeats`) and each reply its index (:class:`~.timing.Observed`), what
    :func:`~.timing.combine_local` reads as the same observations (the first of the worst is
    the one shown, its evidence the first reply's; an equal later one is never shown). A
    run kept two ``(Measured, tainted, place)`` a reply, its evidence maker and place,
    ~650 bytes a reply (issue 22, memory21: 0.97 MB of a sensor's pass at an hour). The
    first tainted observation (the link's irregular stamps, a stall of the tool's host)
    turns it into the list one by one, the folded ones read out in order: those are rare,
    and :func:`~.timing.combine_local` reads them each with its own taint and place.

    Not ``placed`` (a virtual clock or a capture's grid, no stalls of the tool's host: no
    observation can be tainted and no place or order is read) each reply is counted, not
    indexed (:class:`~.timing.Observed` not placed: the indexes were 12 bytes a reply a
    rule, memory24): what is held is bounded by the distinct values."""

    __slots__ = ("_each", "_index", "_observed", "_placed", "_repeats")

    def __init__(self, placed: bool) -> None:
        self._placed = placed  # whether the places are kept (else each is None)
        self._observed = Observed(placed)
        self._repeats: Repeats[Measured] = Repeats()
        self._index: dict[int, int] = {}  # id of a distinct object -> its index
        self._each: list[Observation] | None = None  # one by one, once one is tainted

    def add(self, observations: list[Observation]) -> None:
        """The next observations, in order."""
        for o in observations:
            if self._each is not None:
                self._each.append(o)
                continue
            judged, tainted = o[0], o[1]
            if tainted is not False or type(judged) is not Measured:
                self._each = [*self._observed, o]
                continue
            place = (o[2] if len(o) > 2 else None) if self._placed else None  # type: ignore[misc]
            observed = self._observed
            first = self._repeats.first(judged.measured, judged.uncertainty)
            if first is None:
                i = self._index[id(judged)] = len(observed.distinct)
                observed.distinct.append(self._repeats.keep(judged))
                observed.counts.append(1)
            else:
                i = self._index[id(first)]
                observed.counts[i] += 1
            observed.observe(i, place)

    def observed(self) -> list[Observation]:
        """What :func:`~.timing.combine_local` reads: the folded observations, or the list."""
        return self._observed if self._each is None else self._each  # type: ignore[return-value]


class ReplyGaps:
    """:func:`judge_gaps` over a recording read a window at a time (issue 22's windowed
    judge): each window's segments :meth:`add`-ed in order, the findings those of the whole
    recording's segments. A gap lies inside one segment (one transmission's reply and what
    followed it), so the windows' gaps in order are the whole run's; carried across windows:
    the distinct gaps judged so far (each judged once, counted) and R-7.0-01's gaps in or
    maybe in the tolerance band with the count of all."""

    def __init__(
        self, uncertainty: float | StampUncertainty, stalls: list[Stall] | None = None
    ) -> None:
        self.stamps = stamps = stamp_uncertainty(uncertainty)
        self.stalls = stalls  # the tool's host stalls, as judge_gaps reads them
        base = stamps.base
        # on one uncertainty and no stalls, combine_local reads no gap's place or order
        # (real_time is False: none is decided by place, none set aside): counted
        self._alike = _GapsAlike(base, placed=False) if _alike(stamps) and not stalls else None
        self._each: list[Observation] = []
        self._judged: dict[tuple[float, float, str], Measured] = {}
        self._tolerance = _ToleranceUse(base, stalls)

    def add(self, segs: list[Segment]) -> None:
        """The reply character gaps of ``segs`` (the next window's segments)."""
        if self._alike is not None:
            self._alike.add_segments(segs, self._tolerance)
            return
        gaps = _cut_gaps(segs)
        self._each += _observe_each(gaps, self.stamps, self._judged, self.stalls)
        self._tolerance.add(gaps)

    def findings(self) -> list[Finding]:
        """R-7.0-12 and R-7.0-01 over everything added."""
        observed = self._alike.observed if self._alike is not None else self._each
        gap_finding = combine_local(
            "R-7.0-12", observed, "character gap", real_time=self.stamps.local is not None
        )
        return [gap_finding, self._tolerance.finding()]


def _tolerance_finding(
    sure: list[tuple[float, str]],
    maybe: list[tuple[float, str]],
    count: int,
    uncertainty: float,
    held: list[tuple[float, str, Stall]] | None = None,
    such: tuple[int, int] | None = None,
) -> Finding:
    """R-7.0-01's finding from the ``(gap, where)`` surely and possibly inside the band, out
    of ``count`` gaps judged (:func:`_judge_tolerance_use`); ``held``: those surely in it
    whose stamps a stall of the tool's own host may have moved, with the stall (truth30):
    INCONCLUSIVE naming it unless a gap outside every stall FAILs the rule. ``such``: how
    many are surely and maybe in the band, where the lists hold only the first few
    (:class:`_ToleranceUse`); None: all of them."""
    n_sure, n_maybe = (len(sure), len(maybe)) if such is None else such
    if sure:
        return _leaning(sure, count, uncertainty, n_sure)
    if held:
        gap, where, stall = held[0]
        return stalled_interval(_leaning([(gap, where)], count, uncertainty), stall)
    if maybe:
        gap, where = maybe[0]
        return Finding(
            "R-7.0-01",
            Verdict.INCONCLUSIVE,
            f"{n_maybe} gap(s) such as {gap * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} may lie "
            "in the 1.66..2.06 ms band, where no tolerance applies",
            evidence=[where],
            measured_ms=round(gap * 1e3, 3),
            limit_ms=INTER_CHAR_GAP_MAX * 1e3,
            uncertainty_ms=round(uncertainty * 1e3, 3),
        )
    if not count:
        return Finding("R-7.0-01", Verdict.INCONCLUSIVE, "no character gap observed")
    return Finding(
        "R-7.0-01",
        Verdict.PASS,
        f"{count} character gaps: none leans on a tolerance the rule does not grant; "
        "±0.40 ms applied to every other limit",
        observed=count,
    )


#: A start-to-start spacing below half a frame (twice the nominal rate) is no character a
#: 1200-baud UART receives: on a link with uncertain stamps it is the stamping's, not a rate.
IMPOSSIBLE_SPACING = CHAR_TIME / 2


def judge_reply_bit_rate(segs: list[Segment], uncertainty: float | StampUncertainty) -> Finding:
    """R-4.1-01 (decision A14: 1200 baud ±2%). Back-to-back characters start one frame apart,
    so the shortest start-to-start spacing inside a reply is at least one frame (8.17 ms at
    +2%). A shorter spacing proves the rate too high. A rate too low cannot be told apart from
    an allowed inter-character gap unless some characters come back to back (spacing within
    the ±2% band), so without such a pair the verdict is INCONCLUSIVE, never a guess.
    One :meth:`ReplyBitRate.add` of every segment (the windowed judge's code path)."""
    rate = ReplyBitRate(uncertainty)
    rate.add(segs)
    return rate.finding()


class ReplyBitRate:
    """:func:`judge_reply_bit_rate` over a recording read a window at a time (issue 22's
    windowed judge): each window's segments :meth:`add`-ed in order, the finding that of the
    whole recording's segments. A spacing lies inside one reply (one segment), so the
    windows' spacings in order are the whole run's; carried across windows: how many, the
    least ``(spacing, command)`` so far (each window's pairs compared against it, in order,
    as one pass over the whole run compares them) and of the spacings surely too short
    their count and least, never the list."""

    def __init__(self, uncertainty: float | StampUncertainty) -> None:
        self.stamps = stamp_uncertainty(uncertainty)
        self.count = 0
        self.least: Spacing | None = None
        self.fast = 0
        self.fastest: Spacing | None = None

    def add(self, segs: list[Segment]) -> None:
        """The reply character spacings of ``segs`` (the next window's segments)."""
        count, self.least, fast = _spacings(segs, self.stamps, self.least)
        self.count += count
        self.fast += len(fast)
        if fast:
            least = min(fast)
            self.fastest = least if self.fastest is None else min(self.fastest, least)

    def finding(self) -> Finding:
        """R-4.1-01 over everything added."""
        return _bit_rate_finding(self.stamps, self.count, self.least, self.fast, self.fastest)


def _bit_rate_finding(
    stamps: StampUncertainty, count: int, least: Spacing | None, fast: int,
    fastest: Spacing | None,
) -> Finding:  # fmt: skip
    """R-4.1-01 from :class:`ReplyBitRate`'s figures: ``count`` spacings, the ``least``, and
    ``fast`` of them surely too short, the least of those ``fastest``."""
    uncertainty = stamps.base
    if least is None:
        return Finding("R-4.1-01", Verdict.INCONCLUSIVE, "no multi-character reply observed")
    shortest, text = least
    low = CHAR_TIME * 0.98
    where = [f"in reply to {escape(text)}"]
    if stamps.local is not None and shortest + 2 * uncertainty < low:
        if not sustained(fast, count):  # a few bursts of a stalling host
            return Finding(
                "R-4.1-01",
                Verdict.INCONCLUSIVE,
                f"{fast} of {count} character spacings are shorter than a frame "
                f"(shortest {shortest * 1e3:.2f} ms); too few, or too near irregular stamps, "
                "to tell a fast bit rate from bursts of the link",
                evidence=where,
                observed=count,
            )
        shortest, text = fastest or least  # fast > 0 here: sustained() is False for none
        where = [f"in reply to {escape(text)}"]
    if shortest < IMPOSSIBLE_SPACING and (uncertainty > 0 or stamps.local is not None):
        return Finding(
            "R-4.1-01",
            Verdict.INCONCLUSIVE,
            f"the link's stamps put two reply characters {shortest * 1e3:.3f} ms apart, "
            "shorter than any character a 1200-baud receiver can frame: the stamps (a burst "
            "of one read), not the sensor, made that spacing, and it is no bit rate; undecided",
            evidence=where,
            observed=count,
        )
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
    finding = judge_rate(
        "shortest character start-to-start spacing", shortest, 2 * uncertainty, where
    )
    if finding.verdict is Verdict.FAIL:  # too slow or gapped: not decidable, see docstring
        finding.verdict = Verdict.INCONCLUSIVE
        finding.detail += " (no back-to-back characters: rate and gaps cannot be separated)"
    baud = 10 / shortest if shortest > 0 else float("inf")
    finding.detail += f"; about {baud:.0f} baud from {count} spacings"
    return finding


Spacing = tuple[float, str]  # a start-to-start spacing (s) and the command it answered


def _spacings(
    segs: list[Segment], stamps: StampUncertainty, least: Spacing | None = None
) -> tuple[int, Spacing | None, list[Spacing]]:
    """:func:`judge_reply_bit_rate`'s pass over every pair of consecutive reply characters:
    how many, the least ``(spacing, command)`` as ``min`` of them all gives it (the first
    least spacing, ties by the command's text), and those surely too short even with the
    stamps' local uncertainty. Kept as it goes, not as a list of every pair (tens of
    thousands a run, once each) and a ``min`` over it. ``least``: the least of the pairs
    before ``segs`` (a window's: :class:`ReplyBitRate`), which each pair is compared with."""
    if stamps.local is None:
        return _spacings_alike(segs, stamps.base, least)
    count = 0
    fast: list[Spacing] = []
    between = stamps.between
    low = CHAR_TIME * 0.98
    for seg in segs:
        text = seg.text
        for run in [seg.reply, *runs(seg.later)]:
            count += max(len(run) - 1, 0)
            for a, b in zip(run, run[1:], strict=False):
                spacing = b.start - a.start
                # (spacing, text) < least, as min() compares: the float first, then the text
                if least is None or (spacing <= least[0] and (spacing, text) < least):
                    least = (spacing, text)
                if spacing + 2 * between(a.start, b.end) < low:
                    fast.append((spacing, text))
    return count, least, fast


def _spacings_alike(
    segs: list[Segment], base: float, least: Spacing | None = None
) -> tuple[int, Spacing | None, list[Spacing]]:
    """:func:`_spacings` where every pair has the stamps' one uncertainty ``base`` (a virtual
    clock, a capture's sample grid): a run's spacings subtracted in C, its least by ``min``
    (the least ``(spacing, command)`` of a run is its least spacing's, and ``min`` keeps the
    first of equal ones, as the pair-by-pair rule does), the too-short ones in one pass. A
    run with a NaN spacing (stamps no clock gives) goes pair by pair, where the order of
    comparisons with NaN decides."""
    count = 0
    fast: list[Spacing] = []
    low = CHAR_TIME * 0.98
    twice = 2 * base  # 2 * between(...) of every pair
    for seg in segs:
        text = seg.text
        for run in [seg.reply, *runs(seg.later)]:
            if len(run) < 2:
                continue
            starts = [e.start for e in run]
            spacings = list(map(sub, starts[1:], starts))
            count += len(spacings)
            if any(map(isnan, spacings)):
                for spacing in spacings:
                    if least is None or (spacing <= least[0] and (spacing, text) < least):
                        least = (spacing, text)
            else:
                spacing = min(spacings)
                if least is None or (spacing <= least[0] and (spacing, text) < least):
                    least = (spacing, text)
            fast += [(spacing, text) for spacing in spacings if spacing + twice < low]
    return count, least, fast


def judge_rate(what: str, measured: float, uncertainty: float, evidence: list[str]) -> Finding:
    """R-4.1-01 on one measured frame time (a frame's length, or the spacing of two frames
    back to back): decision A14, 1200 baud ±2 %, no further tolerance."""
    return judge_window(
        "R-4.1-01",
        what,
        measured,
        uncertainty,
        low=CHAR_TIME * 0.98,
        high=CHAR_TIME * 1.02,
        tolerance=0.0,
        evidence=evidence,
        decision="A14",
    )


def judge_frame_lengths(
    frames_at: list[tuple[Event, str]], uncertainty: float | StampUncertainty
) -> Finding:
    """R-4.1-01 (decision A14: 1200 baud ±2%) where each character event lasts its own
    measured frame (a version-2 harness: a firmware kit rebuilds frames from pin writes):
    ten bits of the sender's, so a frame's length is its bit rate, too slow as well as too
    fast, with no back-to-back pair needed. ``frames_at``: each frame and where it was."""
    if not frames_at:
        return Finding("R-4.1-01", Verdict.INCONCLUSIVE, "no character observed")
    base = stamp_uncertainty(uncertainty).base
    lengths = [(e.end - e.start, where) for e, where in frames_at]
    worst, where = max(lengths, key=lambda pair: abs(pair[0] - CHAR_TIME))
    finding = judge_rate("frame length (ten bits)", worst, 2 * base, [where])
    low, high = min(n for n, _ in lengths), max(n for n, _ in lengths)
    finding.detail += (
        f"; {len(lengths)} frames {low * 1e3:.3f}..{high * 1e3:.3f} ms, "
        f"about {10 / worst:.0f} baud at the farthest"
    )
    return finding


def judge_reply_frame_lengths(
    segs: list[Segment], uncertainty: float | StampUncertainty
) -> Finding:
    """R-4.1-01 from the length of every reply frame (:func:`judge_frame_lengths`)."""
    frames_at = [
        (e, f"in reply to {escape(seg.text)}")
        for seg in segs
        for run in [seg.reply, *runs(seg.later)]
        for e in run
    ]
    return judge_frame_lengths(frames_at, uncertainty)


# -- framing of every reply -------------------------------------------------------------------
def _starts_measurement(text: str) -> bool:
    """Whether the command ``text`` starts a measurement: the one a later unasked line
    (its service request) belongs to."""
    try:
        return parse_command(text).kind in MEASUREMENT_KINDS
    except CommandError:
        return False


def judge_framing(
    segs: list[Segment],
    uncertainty: float | StampUncertainty = 0.0,
    own: str | None = None,
    stalls: list[Stall] | None = None,
) -> list[Finding]:
    """R-4.1-02 (7E1 parity), R-4.2-02 (printable), R-4.2-03 (>= 3 chars, CR LF), R-4.3-01
    (the responding sensor's address first) over every ASCII reply and service request.

    ``own``: the sensor's address, see :func:`_expected_addresses`.

    A reply is framed by its protocol end, never by a gap (:class:`Segment`); unsolicited
    characters after it are framed at each LF, and at a gap only where it is surely there
    given the stamps' ``uncertainty``. What the tool's next transmission talked over (the
    DUT's characters meeting it: ``contention``) is no DUT's text, and the part before it
    was cut by the tool, not by the DUT: neither is judged here. One :meth:`Framing.add`
    of every segment (the windowed judge's code path). ``stalls``: the tool's own host
    stalls the link noted (:func:`~conformance.links.host_stall.stalls`), see :class:`Framing`."""
    framing = Framing(uncertainty, own, stalls)
    framing.add(segs)
    return framing.findings()


def maybe_met(seg: Segment, nxt: Segment, uncertainty: float) -> bool:
    """Whether the tool's next transmission ``nxt`` (its break, else its first character)
    may have met the last character the sensors sent after ``seg``: that character started
    before it and ended less than the stamps' uncertainty before it began, or after (the
    engine's "maybe collided" NOTE, :func:`~conformance.tool_recorder.contention.
    maybe_note_text`). The view places such a character in ``seg`` (it started first), not
    in ``nxt``'s contention, and :class:`Framing` took it for the sensor's text: a stray '#'
    that the tool's break began 1 ms before the end of, on ±5 ms stamps (RFC 2217), FAILed
    R-4.1-02 on a parity error the break may have made, and R-4.2-03/R-4.3-01 on a character
    the break may have garbled. On exact stamps only a real overlap counts (a sim bus
    never makes one)."""
    heard = seg.later or seg.reply
    if not heard:
        return False
    last = heard[-1]
    start = (nxt.break_event or nxt.command[0]).start
    return last.start < start < last.end + max(uncertainty, last.uncertainty)


class Framing:
    """:func:`judge_framing` over a recording read a window at a time (issue 22's windowed
    judge): each window's segments :meth:`add`-ed in order, the findings those of the whole
    recording's segments. Carried across windows: the tally (counts, the first labels and
    every violation), the last reply's address, the address of the last reply that started
    a measurement and the one the last reply showed; and a window's last segment, judged
    only once the next segment is known (whether that one's contention cut it: the next
    window's first), or at :meth:`findings`."""

    def __init__(
        self,
        uncertainty: float | StampUncertainty = 0.0,
        own: str | None = None,
        stalls: list[Stall] | None = None,
    ):
        self.stamps = stamp_uncertainty(uncertainty)
        self.own = own
        #: the tool's host stalls: a segment one may have held up is framed by stamps the
        #: host moved (a read cut, the rest a late burst), so a violation it shows is
        #: INCONCLUSIVE with the stall named, never FAIL (:class:`~.stalled.StalledTally`)
        self.stalls = stalls or []
        self.tally = Tally(("R-4.1-02", "R-4.2-02", "R-4.2-03", "R-4.3-01"))
        self.last_address: int | None = None
        self.started: str | None = None  # the address of the last reply starting a measurement
        self.shown: str | None = None  # the address the last reply beginning with its own showed
        self._pending: Segment | None = None  # the last segment added, not judged yet
        self._open_text = False  # multi-line text a command talked over, its ETX not yet seen
        self._before: Segment | None = None  # the last segment judged

    def add(self, segs: list[Segment]) -> None:
        """The replies and later lines of ``segs`` (the next window's segments)."""
        for seg in segs:
            pending = self._pending
            if pending is not None:
                cut = (
                    bool(seg.contention)
                    or pending.met_by is not None
                    or maybe_met(pending, seg, self.stamps.base)
                )
                self._judge(pending, cut=cut)
            self._pending = seg

    def findings(self) -> list[Finding]:
        """R-4.1-02, R-4.2-02, R-4.2-03 and R-4.3-01 over everything added."""
        if self._pending is not None:
            self._judge(self._pending, cut=False)
            self._pending = None
        return self.tally.findings()

    def _judge(self, seg: Segment, *, cut: bool) -> None:
        """One segment; ``cut``: the next transmission's contention met what followed it."""
        tally = self.tally
        if self.stalls:
            heard = seg.later or seg.reply or seg.contention
            end = heard[-1].end if heard else seg.command_end
            start = (seg.break_event or seg.command[0]).start
            tally = through_stall(tally, stalled_over(self.stalls, start, end))
        earlier = _unanswered_before(self._before, seg)
        self._before = _carried(earlier, seg)
        if seg.reply:
            self.last_address = last_address = seg.reply[0].char7
            if _starts_measurement(seg.text):
                self.started = chr(last_address)
        # characters cut off by the next transmission collided with it: what is left of
        # them says nothing about framing (the collision is judged by the rule it breaks)
        later = [] if cut else frames(seg.later, self.stamps.between)
        tool_cut = cut and not seg.reply_ended and not seg.later  # the tool spoke over it
        reply = [seg.reply] if seg.reply and not seg.binary_reply and not tool_cut else []
        chunks = reply + later
        still_open, hidden = self._open_text, self._hides(seg)
        if reply and _packet_late(tally, seg, earlier, self.stamps.base):
            chunks = later
            reply = []
        for n, chunk in enumerate(chunks):
            is_reply = n == 0 and bool(reply)
            label = f"{'reply to' if is_reply else 'later, after'} {escape(seg.text)}"
            bad, text = _parity_errors_and_text(chunk)
            tally.observe(label, ids=["R-4.1-02"])
            if bad:
                tally.fail(
                    "R-4.1-02",
                    label,
                    f"{len(bad)} character(s) with wrong parity, first 0x{bad[0].wire:02X}",
                )
            if hidden:  # the rest of a multi-line text the command talked over
                hidden = self._open_text = chunk[-1].char7 != ETX
                why = (
                    f"'{escape(text[:40])}' is the rest of multi-line text the sensor began "
                    "during the command (a late reply the tool's retry talked over; R-7.0-10 "
                    "judges its timing): not framed as a reply"
                )
                for rid in ("R-4.2-02", "R-4.2-03", "R-4.3-01"):
                    tally.undecide(rid, label, why)
                continue
            if seg.multiline and is_reply:  # decision A10: each line is framed on its own
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
            # a command the DUT talked over was heard in pieces, if at all: the reply answers
            # what the sensor made of them (a sensor's service request cut 0IMC3! so that it
            # answered '3!' at its old address), so its address is not this command's to judge
            talked_over = bool(seg.contention)
            expected = expected_reply_address(seg.text) if is_reply and not talked_over else None
            if not is_reply:
                expected = chr(self.last_address) if self.last_address else None
            tally.observe(label, ids=["R-4.3-01"])
            if is_reply and expected and body[:1] == expected:
                self.shown = expected
            allowed = _expected_addresses(
                expected, self.started if not is_reply else None, self.shown, self.own
            )
            if expected and body[:1] not in allowed:
                rest = still_open and is_reply  # maybe the next line of open text
                earlier_one = earlier if is_reply else None
                _wrong_address(tally, label, text, body[:1], expected, earlier_one, open_text=rest)

    def _hides(self, seg: Segment) -> bool:
        """Whether ``seg``'s text is the rest of multi-line text a command talked over, to
        its ETX (not framed); so is what the next command talked over before that ETX (a
        long line met the next retry). The text stays open (``_open_text``) through a
        command the sensor sent nothing after: it may still go on past it."""
        met = bool(seg.contention) and seg.contention[0].start < seg.command_end
        still_open = self._open_text
        hidden = self._open_text = talked_through(seg) or (still_open and met)
        if still_open and not (seg.reply or seg.later or seg.contention):
            self._open_text = True  # a silent command: the text may still go on after it
        return hidden


def _packet_late(tally: Tally, seg: Segment, earlier: Segment | None, uncertainty: float) -> bool:
    """Whether ``seg``'s reply may be the binary packet of the unanswered aDBn! before it
    (``earlier``, :func:`_unanswered_before`), late: begun too late to be a timely answer to
    ``seg``'s command (past R-7.0-10's 15.40 ms and the stamps' ``uncertainty``) and within
    the 87 ms a late start is believed after the aDBn!. An 8N1 packet is neither printable
    nor ended by CR LF, so no reply's framing to judge; the rules it would judge undecided
    on ``tally``. A sensor 80 ms late, deaf until it answers, sent 0DB999!'s empty packet
    '0<0x00><0x00><0x00><0x0F><0x00>' 25 ms after the 0M! after it: R-4.2-02/-03 FAILed "reply
    to 0M!" beside never-standby, partial-command-accepted and stays-awake-after-foreign
    (replies-after-retry, truth18). A timely reply after a silent aDBn! is its own
    (binary-no-empty-packet)."""
    if earlier is None or not earlier.binary_reply:
        return False
    start = seg.reply[0].start
    if start - seg.command_end <= RESPONSE_START_MAX + TOLERANCE + uncertainty:
        return False
    if not 0 < start - earlier.command_end <= NO_BREAK_WINDOW:
        return False
    label = f"reply to {escape(seg.text)}"
    why = (
        f"may be {escape(earlier.text)}'s late binary packet, not framed as a reply "
        "(R-7.0-10 judges its timing)"
    )
    for rid in ("R-4.1-02", "R-4.2-02", "R-4.2-03", "R-4.3-01"):
        tally.undecide(rid, label, why)
    return True


def _wrong_address(
    tally: Tally,
    label: str,
    text: str,
    named: str,
    expected: str,
    earlier: Segment | None,
    *,
    open_text: bool = False,
) -> None:
    """R-4.3-01 for a reply ``text`` whose body starts with ``named``, not ``expected``: a FAIL, or
    undecided where a reply names the unanswered command before it (``earlier``,
    :func:`_unanswered_before`), whose late reply it may be (a sensor 80 ms late answered z!
    over the 0! after it: 'z<CR><LF>' FAILed as 0!'s, answers-foreign-address +
    replies-after-retry, truth15); or where it may be the next line of multi-line text a
    command talked over whose ETX has not come, only silent commands between (``open_text``):
    a line of that text need not start with the address. replies-after-retry beside
    multiline-slow-lines: 0XHELP!'s first line met the retry, the next 0XHELP! went unheard,
    and the second line 'aXSN! serial number; ...', 200 ms after the first, came in 0M1!'s
    listen: R-4.3-01 FAILed "reply to 0M1! starts with 'a'" (truth21)."""
    if open_text:
        tally.undecide(
            "R-4.3-01",
            label,
            f"'{escape(text)}' may be the next line of multi-line text the sensor began "
            "earlier (no ETX heard yet; R-7.0-10 judges its timing)",
        )
        return
    if earlier is not None:
        tally.undecide(
            "R-4.3-01",
            label,
            f"'{escape(text)}' may be {escape(earlier.text)}'s late reply "
            "(R-7.0-10 judges its timing)",
        )
        return
    tally.fail(
        "R-4.3-01",
        label,
        f"reply '{escape(text)}' starts with '{escape(named)}', not the address '{expected}'",
    )


def _expected_addresses(
    expected: str | None, unsolicited: str | None, shown: str | None, own: str | None
) -> tuple[str | None, ...]:
    """The first characters R-4.3-01 takes in a reply whose command named ``expected`` (the
    last reply's address for characters sent unasked).

    ``unsolicited``: a service request may name the measurement it belongs to, the last one
    started (a sensor that answered zI! for 'z', answers-foreign-address, sends aC!'s request
    as '0': seed 4141 FAILed it against 'z'). ``own``, the address the sensor was judged at,
    until a reply has ``shown`` it elsewhere (one that began with its command's address): a
    reply that starts with it after a command for another address has the responding
    sensor's address first, and that it answered there at all is another rule's (the
    sixteenth round's lagopus sketch at '5' answered the ?!s it had kept while booting 1.5 ms
    after the tool's '0!': R-4.3-01 FAILed "reply '5<CR><LF>' starts with '5', not the address
    '0'"). A sensor moved to '9' that answers '9!' with '0' is still FAILed."""
    return (expected, unsolicited, shown or own)


def _parity_errors_and_text(chunk: list[Event]) -> tuple[list[Event], str]:
    """The characters of ``chunk`` failing ``Event.parity_ok``, and its text (parity
    stripped): :func:`judge_framing` asks both of every reply and service request, a run's
    tens of thousands of characters, which the wire bytes answer in two C passes (the list
    of errors made only where there are some)."""
    wires = wire_bytes(chunk)
    if wires is None:
        return [e for e in chunk if not e.parity_ok], "".join(chr(e.char7) for e in chunk)
    bad = [e for e in chunk if not e.parity_ok] if wires.translate(None, GOOD_PARITY) else []
    return bad, wires.translate(SEVEN_BITS).decode("ascii")
