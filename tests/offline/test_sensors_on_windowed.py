"""The sensors on a bus found a window at a time (issue 22's windowed judge: the rule set
from a pre-scan of the windows as they come): ``heard.SensorsOn`` given each window's
exchanges (``view.windows.rebuild_windowed``) finds the sensors, their first addresses and
identifications, that :func:`~conformance.offline.heard.sensors_on` finds in the whole
recording. The cases a wrong merge gets wrong: a sensor moved by ``aAb!`` in one window and
heard at its new address in the next (one sensor, not two), and an ``aI!`` heard windows
after the sensor's first reply (its identification and so the rule set's version)."""

from __future__ import annotations

from conformance.offline.heard import SensorsOn, sensors_on
from conformance.view.rebuilt_records import rebuild_records
from conformance.view.segments import read_view
from conformance.view.windows import rebuild_windowed, window_starts
from tests.support.bus_of_sensors import as_heard, bus_of_sensors, serial


def _windowed(events: list) -> tuple[list, list]:
    """The sensors found window by window, and the whole recording's."""
    whole = read_view(events)
    found = SensorsOn()
    windows = 0
    for part in rebuild_windowed(events, whole):
        found.add(part.exchanges)
        windows += 1
    assert windows == len(window_starts(whole)) >= 2
    return found.sensors(), sensors_on(rebuild_records(whole).exchanges)


def test_a_sensor_moved_in_one_window_and_heard_in_the_next_is_one_sensor():
    bus, recorder = bus_of_sensors("30")
    recorder.acknowledge("3")
    assert recorder.change_address("5", "0").ok
    assert recorder.identify("5").ok  # its next window: still the sensor first heard at 0
    assert recorder.change_address("0", "5").ok
    got, expected = _windowed(as_heard(bus))
    assert got == expected
    assert [s.address for s in got] == ["0", "3"]
    assert got[0].identity is not None and got[0].identity.optional == serial("0")


def test_an_identification_heard_windows_after_the_first_reply_is_kept():
    bus, recorder = bus_of_sensors("03")
    recorder.acknowledge("0")
    recorder.acknowledge("3")
    recorder.identify("3")
    recorder.identify("0")
    got, expected = _windowed(as_heard(bus))
    assert got == expected
    assert [s.identity.optional for s in got if s.identity] == [serial("0"), serial("3")]
    assert got[0].claim().version == "14"
