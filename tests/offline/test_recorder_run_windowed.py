"""The passive recorder run judged a window at a time (issue 22): every recorder case reads
:func:`~conformance.offline.recorder_windows.recorder_findings`, the recorder's folds fed
the windows :func:`~conformance.view.windows.stream_windows` cuts from the loaded
recording's events, each window's view read alone; its findings must be the whole-run
functions' over the whole view (the passive cases' code path before, R-7.0-02/-06,
R-7.0-17, R-7.1-01, R-4.2-01, R-4.4-04, R-4.3-01, R-7.0-13, R-4.1-01, R-4.4.5-04..07,
R-4.4.7-06, R-4.4.8-05, R-5.1-04, R-5.2-08, R-7.2-01..06, R-4.3-03/-04).

The recordings put a rule's evidence across a window cut: a measurement's data read in a
window after its start (0MC!'s CRC expectation carried to a 0D0! read again after 1I!), a
command's retries over several break sequences, the tally and the addresses over every
window; a wrong merge (a fold started afresh per window, a window skipped or fed twice, the
events not in the view's order) gives other findings."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.judges.recorder.breaks import judge_break_rules, judge_breaks
from conformance.judges.recorder.capabilities import judge_addresses
from conformance.judges.recorder.collection import judge_data_collection, judge_high_volume
from conformance.judges.recorder.commands import (
    judge_character_gaps,
    judge_command_bit_rate,
    judge_command_text,
)
from conformance.judges.recorder.measurements import observed_measurements
from conformance.judges.recorder.retries import judge_retries
from conformance.judges.recorder.waits import judge_concurrent_waits, judge_measure_waits
from conformance.links.base import LinkInfo
from conformance.offline import recorder_windows
from conformance.offline.recorder_windows import (
    RecorderFindings,
    by_start,
    judge_windows,
    recorder_findings,
)
from conformance.replay.recording_link import RecordingLink, RecordingSpec
from conformance.transcript import Event, EventKind, Transcript
from conformance.verdicts import Verdict
from conformance.view.segments import read_view
from conformance.view.windows import stream_windows
from tests.support.bus_of_sensors import as_heard, bus_of_sensors, start
from tests.support.windowed_judges import at_every_break

U = 1e-6  # a 1 MHz capture's stamps


def _whole(events: list[Event]) -> RecorderFindings:
    """The findings the passive recorder cases made before, from the whole view: the
    measurement rules' whole-list functions over :func:`observed_measurements`."""
    view = read_view(events)
    taken = observed_measurements(view, U)
    return RecorderFindings(
        judge_breaks(view, U), judge_break_rules(view, U), judge_command_text(view, U),
        judge_character_gaps(view, U), judge_command_bit_rate(view, U),
        judge_measure_waits(taken, U), judge_concurrent_waits(taken, U),
        judge_data_collection(taken),
        [f for f in judge_high_volume(taken, True) if f.requirement != "R-5.4-01"],
        judge_retries(view, U), judge_addresses(view, U), 1, len(taken),
    )  # fmt: skip


def _alike(found: RecorderFindings, whole: RecorderFindings) -> bool:
    """Every finding (detail, evidence) and the count of measurements the same; the window
    count apart."""
    return replace(found, windows=1) == whole


def _bus() -> list[Event]:
    """Sensor 0's D replies after ``0MC!`` lack their CRC: each ``0D0!`` retried over three
    break sequences; then ``1I!``, ``3!`` unanswered (retried), and ``0D0!`` read again in a
    window of its own, still judged by 0MC!'s CRC expectation; then ``1M!`` and its data."""
    bus, recorder = bus_of_sensors("01", faults={"0": ["crc-missing"]})
    m = start(recorder, "0MC!")
    recorder.link.wait_until(recorder.link.now() + m.ttt + 0.1)
    recorder.collect(m, force_break=True, max_index=0)
    recorder.identify("1")
    recorder.transact("3!")
    recorder.transact("0D0!", force_break=True)
    m1 = start(recorder, "1M!")
    recorder.link.wait_until(recorder.link.now() + m1.ttt + 0.1)
    recorder.collect(m1, force_break=True)
    return as_heard(bus)


def _link(events: list[Event]) -> RecordingLink:
    info = LinkInfo(kind="capture sr", can_break=False, timing_uncertainty=U)
    return RecordingLink(RecordingSpec("bus.sr", "sr"), info, Transcript(events), U)


def test_the_recorder_run_judges_the_windows_as_the_whole_view():
    events = _bus()
    whole = _whole(events)
    by_rule = {f.requirement: f for f in whole.retries}
    assert by_rule["R-7.2-06"].verdict is Verdict.PASS and by_rule["R-7.2-06"].observed > 3
    assert by_rule["R-7.2-05"].observed >= 2  # both 0D0! groups, the one read again too
    assert whole.measured == 2
    found = recorder_findings(_link(events))
    assert found.windows > 3  # the evidence above lies across the cuts
    assert _alike(found, whole)
    assert recorder_findings(_link(events)) == found  # a pure function of the recording


def test_a_fold_started_afresh_per_window_differs():
    """The merge the windows need: one set of folds over every window. Judging each window
    on its own folds and keeping the last window's findings (or any one) is not the whole."""
    events = _bus()
    whole = _whole(events)
    windows = list(stream_windows(iter(events), uncertainty=U))
    assert len(windows) > 3
    assert not _alike(judge_windows(windows[-1:], U), whole)
    assert not _alike(judge_windows(windows[:-1], U), whole)
    assert not _alike(judge_windows([*windows, windows[-1]], U), whole)
    assert _alike(judge_windows(windows, U), whole)


def test_a_window_cut_at_every_break_judges_as_the_whole():
    """Finer than the product's cut (which never splits a measurement nor a command from its
    retry): what each fold carries from one window to the next is all the next one needs."""
    events = _bus()
    assert _alike(judge_windows(at_every_break(events), U), _whole(events))


def test_a_transcript_out_of_start_order_is_judged_in_the_views_order():
    """A monitor's transcript may hold an event stamped before the one written before it;
    the view reads them by start (stably), and so must the windows: given as written,
    :func:`stream_windows` refuses them."""
    events = _bus()
    moved = list(events)
    i = next(i for i, e in enumerate(moved) if e.kind is EventKind.BREAK and i > 40)
    moved[i], moved[i + 1] = moved[i + 1], moved[i]  # the character after the break first
    assert moved[i].start > moved[i + 1].start
    note = Event(EventKind.NOTE, "bus", 0.0, 0.0, text="a note")  # a view reads none
    moved.insert(5, note)
    with pytest.raises(ValueError, match="out of order"):
        list(stream_windows(iter(moved), uncertainty=U))
    assert list(by_start(moved)) == sorted(events, key=lambda e: e.start)
    assert _alike(recorder_findings(_link(moved)), _whole(moved))


def test_an_ordered_recording_is_not_copied():
    """A capture's decode gives its events by start: they are streamed as they are (one
    iterator over the list, no sorted copy of an hour's events)."""
    events = _bus()
    assert not isinstance(by_start(events), list)
    assert list(by_start(events)) == events


def test_the_passive_recorder_cases_read_the_windowed_findings(tmp_path, monkeypatch):
    """``sdi12-conform judge`` of a bus's recording: the recorder run's cases take their
    findings from :func:`recorder_findings` (made once), not from the whole view."""
    from conformance.cli import main
    from conformance.replay.recording import write_recording

    events = _bus()
    path = tmp_path / "bus.jsonl"
    write_recording(path, [replace(e, origin="bus") for e in events])
    made: list[int] = []
    original = recorder_windows.judge_views

    def counted(views, uncertainty, *stalls):  # type: ignore[no-untyped-def]
        found = original(views, uncertainty, *stalls)
        made.append(found.windows)
        return found

    monkeypatch.setattr(recorder_windows, "judge_views", counted)
    code = main(["judge", str(path), "--role", "recorder", "--report-dir", str(tmp_path / "r")])
    assert code in (0, 1, 2)
    assert len(made) == 1 and made[0] > 3


def test_the_recorder_run_in_order_and_out_of_it():
    """The recorder's findings come from the bus pass's windows
    (:func:`~conformance.offline.sensor_windows.bus_windows`, cut once per recording for
    the sensor runs too), in order and out of it: the findings are the whole view's. (The
    bus pass reads its windows by position in the loaded list, which the loader still
    holds: issue 22's bound needs a store that gives them without it.)"""
    events = _bus()
    moved = list(events)
    i = next(i for i, e in enumerate(moved) if e.kind is EventKind.BREAK and i > 40)
    moved[i], moved[i + 1] = moved[i + 1], moved[i]
    for given in (events, moved):
        assert _alike(recorder_findings(_link(given)), _whole(given))
