"""A recording cut into windows (issue 22's windowed judge, ``conformance.view.windows``):
each window's view, read from its own events alone, is the whole view's transmissions of
that window, and the records rebuilt window by window (what the windows before carried in)
are the whole run's, exchange for exchange and measurement for measurement.

The cases a wrong cut or merge gets wrong: a concurrent measurement pending across a long
idle gap and another sensor's exchange (R-4.4.7-05: a cut at the gap loses its data), an
aM! whose data another sensor's exchange ends (R-4.4.5-06), a data reply read again long
after its aMC! (R-4.4.12-01's CRC: the expectation is carried across the cut), retries
(R-7.2-01: a retry is no window's start), a break that cut into a reply (R-7.2-06: no
window's start either), and a whole bus's identify and concurrent round."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.transcript import Event, EventKind
from conformance.view.rebuilt_records import rebuild_records
from conformance.view.segments import read_view
from conformance.view.windows import (
    rebuild_windowed,
    stream_window_views,
    stream_windows,
    window_events,
    window_starts,
)
from tests.support.bus_of_sensors import (
    ADDRESSES,
    as_heard,
    bus_of_sensors,
    concurrent_round,
    measured_past_another,
    start,
)
from tests.support.hand_events import sent, woken
from tests.support.records_alike import records_fields, view_differences

IDLE = 30.0  # s of silence: far past the standby time (100 ms), as a field logger idles


def _check(events: list, *, min_windows: int = 2) -> list[int]:
    """The windows of ``events`` read alone equal the whole: view and records (the whole
    bus's and each sensor's alone); gives the window starts."""
    whole = read_view(events)
    starts = window_starts(whole)
    assert len(starts) >= min_windows
    windows = list(window_events(events, whole, starts))
    assert len(windows) == len(starts)
    assert [e for w in windows for e in w] == sorted(events, key=lambda e: e.start)
    streamed = list(stream_windows(iter(sorted(events, key=lambda e: e.start))))
    assert [list(map(id, w)) for w in streamed] == [list(map(id, w)) for w in windows]
    assert view_differences(whole, [read_view(w) for w in windows]) == []
    for only in (None, *ADDRESSES):
        expected = rebuild_records(whole, only=only)
        got = records_fields(list(rebuild_windowed(events, whole, only=only)))
        assert got == records_fields([expected]), only
    return starts


def _idle(recorder, seconds: float = IDLE) -> None:
    recorder.link.wait_until(recorder.link.now() + seconds)


def test_a_bus_round_is_cut_between_its_sequences_and_rebuilds_alike():
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES:
        recorder.identify(a)
    concurrent_round(recorder)
    _idle(recorder)
    for a in ADDRESSES:
        recorder.identify(a)
    starts = _check(as_heard(bus))
    view = read_view(as_heard(bus))
    texts = [view.transmissions[i].text for i in starts]
    # each identify opens a window; the concurrent round is one, up to the next identify
    assert texts[: len(ADDRESSES)] == [f"{a}I!" for a in ADDRESSES]
    assert f"{ADDRESSES[0]}C!" in texts
    assert all(not t.endswith("D0!") for t in texts)


def test_a_concurrent_measurement_pending_across_an_idle_gap_is_never_cut():
    """0C! started, the bus idle 30 s, sensor 1 identified, then 0's data: no window may
    begin between 0C! and 0D0! (R-4.4.7-05), however long the gap; a cut at the gap (the
    standby rule alone) would rebuild 0C! without its data."""
    bus, recorder = bus_of_sensors()
    m = start(recorder, "0C!")
    _idle(recorder)
    recorder.identify("1")
    _idle(recorder, m.ttt)
    recorder.collect(m, force_break=True)
    _idle(recorder)
    recorder.identify("3")
    events = as_heard(bus)
    starts = _check(events)
    view = read_view(events)
    texts = [t.text for t in view.transmissions]
    assert texts.index("1I!") not in starts and texts.index("0D0!") not in starts
    assert texts.index("3I!") in starts
    # the wrong cut (at the idle gap before 1I!) fails the merge: 0C! loses its data
    wrong = [0, texts.index("1I!")]
    windows = list(window_events(events, view, wrong))
    parts = [rebuild_records(read_view(w)) for w in windows]
    whole = rebuild_records(view)
    assert [m.value_count for m in whole.measurements] == [whole.measurements[0].count]
    assert [m.data for p in parts for m in p.measurements] == [[]]
    assert records_fields(parts) != records_fields([whole])


def test_an_m_measurement_ended_by_another_sensor_is_cut_there():
    """aM!, then 1I! before its service request, then its D0 after a break (R-4.4.5-06):
    1I! ends the measurement, so a window may begin at 1I! and the D0 reads as no data of
    it, as the whole run reads it."""
    bus, recorder = bus_of_sensors()
    recorder.identify("0")
    measured_past_another(recorder)
    _idle(recorder)
    recorder.identify("0")
    _check(as_heard(bus))


def test_a_crc_expectation_is_carried_across_the_cut():
    """aMC! to a sensor that leaves the CRC off, its data read, the bus idle, another
    command to it, and aD0! again: the re-read's CRC is still expected (the whole run's
    rebuild finds it missing). Rebuilt without the carried expectation, the window would
    take the reply as a plain one: a different record, which the merge check catches."""
    bus, recorder = bus_of_sensors(faults={"0": ["crc-missing"]})
    m = start(recorder, "0MC!")
    _idle(recorder, m.ttt + 0.1)
    recorder.collect(m, force_break=True)
    _idle(recorder)
    recorder.identify("0")
    _idle(recorder)
    recorder.transact("0D0!", force_break=True)
    events = as_heard(bus)
    starts = _check(events, min_windows=3)
    view = read_view(events)
    texts = [t.text for t in view.transmissions]
    again = texts.index("0I!") + 1  # the re-read, then its retries (its CRC missing)
    assert texts[again] == "0D0!" and again in starts
    whole = rebuild_records(view)
    assert not whole.exchanges[-1].ok  # the CRC asked for by 0MC! is missing
    uncarried = [rebuild_records(read_view(w)) for w in window_events(events, view, starts)]
    assert uncarried[-1].exchanges[-1].ok  # no expectation: taken as a plain reply
    assert records_fields(uncarried) != records_fields([whole])


def test_a_retry_never_starts_a_window():
    """A sensor slow to wake (it misses a command after the break): the recorder's retries
    (R-7.2-01), each of the same text, stay with the first attempt in one exchange and one
    window."""
    bus, recorder = bus_of_sensors("0", faults={"0": ["slow-wake"]})
    recorder.identify("0")
    _idle(recorder)
    recorder.identify("0")
    events = as_heard(bus)
    view = read_view(events)
    starts = window_starts(view)
    for i in starts[1:]:
        assert view.transmissions[i].text != view.transmissions[i - 1].text
    _check(events, min_windows=1)


def test_a_break_that_cut_into_a_reply_starts_no_window():
    """The recorder breaks into ``0I!``'s reply 1 ms after its seventh character (a poll
    timeout shorter than the reply) and asks ``1I!``: the break is known to have cut the
    reply only beside it (``cut_by``); a window starting there read the reply alone as the
    sensor's invalid one (R-7.2-05 due), where the whole says the recorder cut it."""
    events: list[Event] = []
    t = sent(events, woken(events, 0.05, "0I!"), "014CONF") + 0.001
    t = sent(events, woken(events, t, "1I!"), "114CONFORM EMU001100\r\n") + 0.2
    t = sent(events, woken(events, t, "3I!"), "314CONFORM EMU001100\r\n")
    whole = read_view(events)
    assert whole.transmissions[0].cut_by is events[11]  # the break before 1I!
    assert _check(events) == [0, 2]


@pytest.mark.parametrize("code", ["C", "CC", "M", "MC"])
def test_rounds_of_every_measurement_kind_rebuild_alike(code):
    bus, recorder = bus_of_sensors()
    for _ in range(2):
        if code.startswith("C"):
            concurrent_round(recorder, code=code)
        else:
            for a in ADDRESSES:
                m = start(recorder, f"{a}{code}!")
                _idle(recorder, m.ttt + 0.1)
                recorder.collect(m, force_break=True)
        _idle(recorder, 1.0)
    _check(as_heard(bus))


def test_streamed_windows_hold_an_open_measurement_until_it_ends():
    """Cut as the events come: while 0C!'s data may still come (sensor 1 identified in
    between, 30 s of idle), no window is given out past 0C!; the windows given out before
    the last event never change afterwards, and notes are left out."""
    bus, recorder = bus_of_sensors()
    recorder.identify("3")
    m = start(recorder, "0C!")
    _idle(recorder)
    recorder.identify("1")
    _idle(recorder, m.ttt)
    recorder.collect(m, force_break=True)
    recorder.identify("3")
    events = sorted(as_heard(bus), key=lambda e: e.start)
    given: list[tuple[int, list]] = []  # how many events had come when each window went
    fed = 0

    def feed():
        nonlocal fed
        for e in events:
            fed += 1
            yield e

    for w in stream_windows(feed()):
        given.append((fed, w))
    texts = [read_view(w).transmissions[0].text for _, w in given]
    assert texts == ["3I!", "0C!", "3I!"]  # 0C! .. its data one window, 1I! inside it
    d0 = next(t for t in read_view(events).transmissions if t.text == "0D0!")
    data = next(i for i, e in enumerate(events) if e is d0.break_event)
    assert given[1][0] > data  # 0C!'s window went only after its data had come
    notes = [replace(events[0], kind=EventKind.NOTE, text="n")]
    assert list(stream_windows(notes + events[:1])) == [events[:1]]


def test_streamed_events_out_of_order_are_refused():
    bus, recorder = bus_of_sensors("0")
    recorder.identify("0")
    events = sorted(as_heard(bus), key=lambda e: e.start)
    with pytest.raises(ValueError, match="out of order"):
        list(stream_windows([events[1], events[0]]))


def test_streamed_windows_read_each_event_about_once(monkeypatch):
    """Where the held events may be cut is asked at every ``SETTLE_BREAKS``-th break, not at
    each: a bus of one sequence a window read every window's view twice (it, then it with the
    next one held), which cost a windowed judge's pass over an hour's capture more than its
    judges. The windows are the same as the whole view's cut, and one asked at every break."""
    from conformance.view import windows

    bus, recorder = bus_of_sensors("013")
    for _ in range(20):
        for a in "013":
            recorder.identify(a)
    events = sorted(as_heard(bus), key=lambda e: e.start)
    read = 0

    def counting(original):  # type: ignore[no-untyped-def]
        def counted(held):  # type: ignore[no-untyped-def]
            nonlocal read
            read += len(held)
            return original(held)

        return counted

    for name in ("read_view", "read_sides"):  # the held events' view (read_sides: sides too)
        if hasattr(windows, name):
            monkeypatch.setattr(windows, name, counting(getattr(windows, name)))
    given = list(stream_windows(iter(events)))
    assert len(given) == 60
    assert read >= len(events)
    assert read <= 1.2 * len(events)  # each asked at every break: 2.0 times
    monkeypatch.undo()
    view = read_view(events)
    assert given == list(window_events(events, view, window_starts(view)))
    monkeypatch.setattr(windows, "SETTLE_BREAKS", 1)
    assert list(stream_windows(iter(events))) == given


@pytest.mark.parametrize("origins", ["bus", "own"])
def test_streamed_window_views_are_each_windows_own(origins):
    """:func:`stream_window_views` gives each window with the view read of it alone: where
    the directions are inferred (origin ``bus``) cut with the sides the held events' read
    inferred, not inferred again; the same transmissions, breaks, characters, unanswerable
    and undirected characters, and the same records rebuilt from them (a measurement, data
    with CRC across windows). With the origins given, each is read as before."""
    bus, recorder = bus_of_sensors("013")
    for a in "013":
        recorder.identify(a)
    m = start(recorder, "0MC!")
    recorder.link.wait_until(recorder.link.now() + m.ttt + 0.1)
    recorder.collect(m, force_break=True)
    for _ in range(20):
        for a in "13":
            recorder.identify(a)
    recorder.transact("0D0!", force_break=True)
    events = as_heard(bus) if origins == "bus" else list(recorder.link.transcript.events)
    events = sorted([e for e in events if e.kind is not EventKind.NOTE], key=lambda e: e.start)
    pairs = list(stream_window_views(iter(events)))
    assert [w for w, _ in pairs] == list(stream_windows(iter(events)))
    assert len(pairs) > 20
    for window, view in pairs:
        assert view_differences(read_view(window), [view]) == []
    carried: dict[str, bool] = {}
    again: dict[str, bool] = {}
    for window, view in pairs:
        mine = rebuild_records(view, carried=carried)
        theirs = rebuild_records(read_view(window), carried=again)
        assert records_fields([mine]) == records_fields([theirs])
