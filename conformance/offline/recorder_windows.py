"""The passive recorder cases' judges run over the recording a window at a time (issue 22).

Every judge the passive recorder cases call (``testcases/passive/test_recorder_7_wire.py``,
``test_recorder_4_4_measurement.py``) is a fold: ``add`` each window's view in order, then
the findings, which are the whole view's (each fold's whole-run function is one ``add``);
the measurement rules' folds ``take`` each measurement :class:`ObservedMeasurements`
found, once it is over, in the order begun (each whole-list function is those ``take``).
:func:`recorder_findings` feeds them all in one pass over the windows
:func:`~conformance.view.windows.stream_windows` cuts from the recording's events as they
come, each window's view read from its own events alone (the directions the cut inferred
over them kept: :func:`~conformance.view.windows.stream_window_views`) and let go once
every fold has taken it; the cases read their findings from the result (made once per
loaded recording).
So the recorder's run reads no whole-run view: what it holds of the recording is one
window's view at a time and what the folds carry (counts, the first few citations, one
observation per distinct value, the measurements still followed: each one, once over, is
judged by the measurement rules' folds and let go, memory27).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from itertools import pairwise
from operator import attrgetter
from typing import TYPE_CHECKING

from ..judges.recorder.breaks import BreakRules, Breaks
from ..judges.recorder.capabilities import Addresses
from ..judges.recorder.collection import DataCollection, HighVolume
from ..judges.recorder.commands import CharacterGaps, CommandBitRate, CommandText
from ..judges.recorder.measurements import ObservedMeasurement, ObservedMeasurements
from ..judges.recorder.retries import Retries
from ..judges.recorder.waits import ConcurrentWaits, MeasureWaits
from ..links.host_stall import Stall
from ..transcript import Event, EventKind
from ..verdicts import Finding
from ..view.segments import TranscriptView, memo, read_view

if TYPE_CHECKING:
    from ..replay.recording_link import RecordingLink


@dataclass(frozen=True)
class RecorderFindings:
    """What the passive recorder cases judge, each as its whole-run function gives it:
    ``judge_breaks``, ``judge_break_rules``, ``judge_command_text``,
    ``judge_character_gaps``, ``judge_command_bit_rate``, the four measurement cases'
    ``judge_measure_waits`` (with the stalls), ``judge_concurrent_waits``,
    ``judge_data_collection`` (with the stalls) and ``judge_high_volume``'s R-5.1-04 and
    R-5.2-08 (with the stalls; its R-5.4-01, whether a v1.4 recorder issues both, is not
    judged from a recording, and the two do not read the claim) over
    ``observed_measurements``, ``judge_retries`` and ``judge_addresses``; how many windows
    the recording was read in and how many measurements it showed; the tool's host stalls
    noted in the recording, which the measurement judges read too (truth33). No
    measurement: each was judged once over and let go (memory27)."""

    breaks: list[Finding]
    break_rules: list[Finding]
    command_text: list[Finding]
    character_gaps: list[Finding]
    command_bit_rate: Finding
    measure_waits: list[Finding]
    concurrent_waits: list[Finding]
    data_collection: list[Finding]
    high_volume: list[Finding]
    retries: list[Finding]
    addresses: list[Finding]
    windows: int
    measured: int
    stalls: tuple[Stall, ...] = ()


def judge_windows(
    windows: Iterable[list[Event]], uncertainty: float, stalls: Sequence[Stall] = ()
) -> RecorderFindings:
    """Every fold fed each of ``windows`` (in order, together a recording's events), each
    window's view read alone and let go."""
    return judge_views((read_view(w) for w in windows), uncertainty, stalls)


def judge_views(
    views: Iterable[TranscriptView], uncertainty: float, stalls: Sequence[Stall] = ()
) -> RecorderFindings:
    """Every fold fed each of ``views`` (each window's, read alone, in order), each let go
    once every fold has taken it. No window at all (a recording with no events) is judged
    as the whole-run functions judge an empty view: one empty window. ``stalls``: the tool's
    host stalls noted in the recording (a window's view holds no notes), which the folds
    that read them hold deviations across (truth32). The measurements
    (:class:`ObservedMeasurements`) are handed to the measurement judges' folds as each is
    over, in the order begun, and let go (memory27)."""
    stalls = tuple(stalls)
    breaks, rules = Breaks(uncertainty, stalls), BreakRules(uncertainty, stalls)
    text, gaps = CommandText(uncertainty, stalls), CharacterGaps(uncertainty, stalls)
    rate, taken = CommandBitRate(uncertainty), ObservedMeasurements(uncertainty)
    retries, addresses = Retries(uncertainty, stalls), Addresses(uncertainty)
    folds = (breaks, rules, text, gaps, rate, taken, retries, addresses)
    waits, concurrent = MeasureWaits(uncertainty, stalls), ConcurrentWaits(uncertainty)
    collection, high_volume = DataCollection(stalls), HighVolume(stalls)
    judges = (waits, concurrent, collection, high_volume)
    count = measured = 0

    def judge(over: list[ObservedMeasurement]) -> int:
        for m in over:
            for j in judges:
                j.take(m)
        return len(over)

    for view in views:
        for fold in folds:
            fold.add(view)
        measured += judge(taken.finished())
        count += 1
    if not count:
        view = read_view([])
        for fold in folds:
            fold.add(view)
    measured += judge(taken.rest())
    return RecorderFindings(
        breaks.findings(), rules.findings(), text.findings(), gaps.findings(),
        rate.finding(), waits.findings(), concurrent.findings(), collection.findings(),
        high_volume.collections(), retries.findings(), addresses.findings(), count, measured,
        stalls,
    )  # fmt: skip


def by_start(events: Sequence[Event]) -> Iterator[Event]:
    """``events`` without their notes, in the order a view reads them (by start, stably,
    as :func:`~conformance.view.segments.read_view` sorts them), which
    :func:`~conformance.view.windows.stream_windows` needs: a capture's decode gives them
    so already (no copy made); a transcript whose stamps go back somewhere is sorted."""
    return by_start_again(lambda: iter(events))


def by_start_again(again: Callable[[], Iterable[Event]]) -> Iterator[Event]:
    """:func:`by_start` of the events ``again()`` gives (every event from the first, in
    recorded order, at each call), read as they come: once to see whether they are in
    order, then once more as the windows are cut (issue 22: the recorder's run reads no
    list of a recording's events); sorted into a list only where they are not."""
    if all(a.start <= b.start for a, b in pairwise(_plain(again()))):
        return _plain(again())
    return iter(sorted(_plain(again()), key=attrgetter("start")))


def _plain(events: Sequence[Event]) -> Iterator[Event]:
    """``events`` without their notes (a view reads none)."""
    return (e for e in events if e.kind is not EventKind.NOTE)


def recorder_findings(link: RecordingLink) -> RecorderFindings:
    """:func:`judge_views` over the windows of ``link``'s recording, made once per loaded
    recording (every recorder case reads it): the windows the bus pass cut
    (:func:`~.sensor_windows.bus_windows`, which the sensors on the bus and the notes read
    too), each window's view read again from its events and the sides the cut inferred,
    the views :func:`~conformance.view.windows.stream_window_views` gives (not cut again)."""
    from .sensor_windows import bus_windows, noted_stalls

    def judge() -> RecorderFindings:
        bus = bus_windows(link)
        stalls = noted_stalls(link.transcript.events)
        return judge_views(map(bus.view, range(len(bus))), link.uncertainty, stalls)

    return memo(link, "_recorder_findings", len(link.transcript.events), judge)


__all__ = [
    "RecorderFindings",
    "by_start",
    "by_start_again",
    "judge_views",
    "judge_windows",
    "recorder_findings",
]
