"""The recorder's measurements found a window at a time (issue 22's windowed judge):
:class:`~conformance.judges.recorder.measurements.ObservedMeasurements` given each window's
view, read from its own events alone, in order gives :func:`observed_measurements` of the
whole recording, measurement for measurement, so the passive recorder cases' measurement
rules (R-4.4.5-04..07, R-4.4.7-06, R-4.4.8-05, R-5.1-04, R-5.2-08) judge the same list.

What a measurement reads past its window, and a wrong merge gets wrong: the next command to
its sensor, windows later (``next_start``: R-4.4.8-05's "aM! again"), the commands to other
sensors until then when no data came (``others``: R-4.4.5-06), a data reply read again
after other sensors' exchanges and judged by its measurement's CRC expectation (R-4.4.12-07's
CRC: carried, ``crc_context(pending=)``), and each measurement's place in the whole
recording (``index``)."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.measurements import (
    ObservedMeasurement,
    ObservedMeasurements,
    observed_measurements,
)
from conformance.judges.recorder.waits import judge_measure_waits
from conformance.judges.reply_validity import Reason
from conformance.transcript import Event
from conformance.view.segments import read_view
from conformance.view.windows import stream_windows, window_events, window_starts
from tests.support.bus_of_sensors import as_heard, bus_of_sensors, start
from tests.support.windowed_judges import at_every_break

U = 1e-6  # a 1 MHz capture's stamps


def _windowed(windows: list[list[Event]]) -> list[ObservedMeasurement]:
    taken = ObservedMeasurements(U)
    for window in windows:
        taken.add(read_view(window))
    return taken.measurements()


def _recording() -> list[Event]:
    """``0MC!`` collected (a CRC), two other sensors identified, ``0D0!`` read again with a
    break (its reply judged by 0MC!'s CRC), then ``1M!`` never collected, ``3I!`` and
    ``1M!`` again (the first 1M!'s next start, with 3I! its other, windows later)."""
    bus, recorder = bus_of_sensors()
    m = start(recorder, "0MC!")
    recorder.link.wait_until(recorder.link.now() + m.ttt + 0.1)
    recorder.collect(m, force_break=True)
    recorder.identify("1")
    recorder.identify("3")
    recorder.transact("0D0!", force_break=True)
    start(recorder, "1M!")
    recorder.identify("3")
    again = start(recorder, "1M!")
    recorder.link.wait_until(recorder.link.now() + again.ttt + 0.1)
    recorder.collect(again, force_break=True)
    return as_heard(bus)


@pytest.fixture(scope="module")
def events() -> list[Event]:
    return _recording()


@pytest.fixture(scope="module")
def whole(events: list[Event]) -> list[ObservedMeasurement]:
    found = observed_measurements(read_view(events), U)
    assert [m.start.text for m in found] == ["0MC!", "1M!", "1M!"]
    return found


def test_the_recording_shows_what_crosses_a_cut(events, whole):
    """The evidence each test below leans on: spread over windows :func:`window_starts`
    cuts, so a fold that forgets any of it is caught."""
    view = read_view(events)
    opens = [view.transmissions[i].start for i in window_starts(view)]

    def window(t) -> int:
        return sum(1 for s in opens if s <= t.start)

    crc_m, unread, again = whole
    assert [t.text for t, _ in crc_m.data] == ["0D0!", "0D0!"] and crc_m.command.returns_crc
    assert window(crc_m.data[1][0]) > window(crc_m.data[0][0]) == window(crc_m.start)
    assert [o.text for o in crc_m.others] == ["1I!", "3I!"]  # before the data read again
    assert unread.data == [] and [o.text for o in unread.others] == ["3I!"]
    assert unread.next_start is not None
    assert window(unread.next_start) > window(unread.others[0]) > window(unread.start)
    assert (crc_m.index, unread.index, again.index) == (0, 5, 7)


def test_windows_give_the_whole_recordings_measurements(events, whole):
    view = read_view(events)
    windows = list(window_events(events, view, window_starts(view)))
    assert len(windows) >= 5
    assert _windowed(windows) == whole
    streamed = list(stream_windows(iter(sorted(events, key=lambda e: e.start)), uncertainty=U))
    assert _windowed(streamed) == whole


def test_a_cut_at_every_break_gives_the_whole_recordings_measurements(events, whole):
    """Each measurement's data, others and next start in windows of their own."""
    windows = at_every_break(events)
    assert len(windows) == 9
    assert _windowed(windows) == whole


def test_a_data_reply_read_again_is_judged_by_its_measurements_crc():
    """A sensor whose D replies after ``0MC!`` lack their CRC: ``0D0!`` read again after
    ``1I!``, in a window of its own, is still judged by 0MC!'s CRC expectation, carried
    from the window of 0MC! (a crc-missing problem); a window starting afresh would judge
    it by its look and find it valid (R-4.4.12-07's missing CRC unseen)."""
    bus, recorder = bus_of_sensors(faults={"0": ["crc-missing"]})
    m = start(recorder, "0MC!")
    recorder.link.wait_until(recorder.link.now() + m.ttt + 0.1)
    recorder.collect(m, force_break=True, max_index=0)
    recorder.identify("1")
    recorder.transact("0D0!", force_break=True, retries=False)
    events = as_heard(bus)
    view = read_view(events)
    windows = list(window_events(events, view, window_starts(view)))
    whole = observed_measurements(view, U)
    assert len(windows) == 3  # 0MC! and its data, 1I!, 0D0! read again
    last, problem = whole[0].data[-1]
    assert last.text == "0D0!" and last.start >= windows[2][0].start
    assert problem is not None and problem.reason is Reason.CRC_MISSING
    assert _windowed(windows) == whole


def test_the_waits_judged_from_windows_are_the_whole_recordings(events, whole):
    """R-4.4.5-04..07 over the windowed measurements: the same findings."""
    windowed = _windowed(at_every_break(events))
    assert judge_measure_waits(windowed, U) == judge_measure_waits(whole, U)
