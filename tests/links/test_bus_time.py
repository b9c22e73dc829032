"""The bus-time lower bound a run reports next to its wall time."""

from __future__ import annotations

import pytest

from conformance.links.bus_time import bus_time, uncounted
from conformance.protocol.timing import CHAR_TIME, MARKING_AFTER_BREAK, RELEASE_LINE, RETRY_MIN
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1


class Wire:
    """Builds a transcript on a clock: breaks, commands, replies, pauses."""

    def __init__(self) -> None:
        self.t = 0.0
        self.events: list[Event] = []

    def pause(self, seconds: float) -> Wire:
        self.t += seconds
        return self

    def brk(self, seconds: float = 13e-3) -> Wire:
        self.events.append(Event(EventKind.BREAK, TOOL, self.t, self.t + seconds))
        self.t += seconds
        return self

    def send(self, origin: str, text: str) -> Wire:
        for c in text:
            wire = to_wire_7e1(ord(c))
            self.events.append(Event(EventKind.CHAR, origin, self.t, self.t + CHAR_TIME, wire=wire))
            self.t += CHAR_TIME
        return self


def test_empty_transcript_needs_no_time():
    assert bus_time([]).lower_bound == 0.0


def test_a_plain_exchange_costs_its_frames_break_marking_and_the_dut_delay():
    w = Wire().brk().pause(9e-3).send(TOOL, "0!").pause(9e-3).send(DUT, "0\r\n")
    figures = bus_time(w.events)
    expected = 13e-3 + MARKING_AFTER_BREAK + 5 * CHAR_TIME + 9e-3
    assert figures.lower_bound == pytest.approx(expected)
    assert figures.frames == 5 and figures.breaks == 1
    assert figures.span == pytest.approx(w.t)


def test_tool_patience_is_not_counted_but_forced_waits_are():
    w = Wire().brk().pause(9e-3).send(TOOL, "0!").pause(0.2)  # no reply: only 16.67 ms forced
    w.send(TOOL, "0!").pause(9e-3).send(DUT, "0\r\n").pause(0.3)  # 7.5 ms line release
    w.send(TOOL, "0!")
    lower = bus_time(w.events).lower_bound
    frames = 9 * CHAR_TIME
    forced = 13e-3 + MARKING_AFTER_BREAK + RETRY_MIN + 9e-3 + RELEASE_LINE
    assert lower == pytest.approx(frames + forced)


def test_an_announced_measurement_time_is_forced_even_without_a_service_request():
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    reply_end = w.t
    w.pause(5.2).brk().pause(9e-3).send(TOOL, "0D0!")
    lower = bus_time(w.events).lower_bound
    assert lower >= 5.0  # the 5 s ttt counts from the end of the reply
    assert lower < w.t - reply_end + 0.2  # and is counted once


def test_a_service_request_wait_is_the_sensors_time():
    w = Wire().brk().pause(9e-3).send(TOOL, "0M!").pause(9e-3).send(DUT, "00053\r\n")
    w.pause(1.5).send(DUT, "0\r\n").pause(20e-3).send(TOOL, "0D0!")
    lower = bus_time(w.events).lower_bound
    # the 1.5 s until the service request and ttt overlap: counted once, not twice
    assert 1.5 < lower < 5.0 + 0.2


def test_a_break_does_not_end_a_concurrent_measurements_wait():
    """R-4.4.7-05: a recorder that breaks to talk to another sensor during ``aC!`` still waits
    for ttt before it reads the data, so the whole ttt is forced."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    reply_end = w.t
    w.pause(0.05).brk().pause(9e-3).send(TOOL, "zI!")  # another sensor's command, no reply
    w.pause(5.2).brk().pause(9e-3).send(TOOL, "0D0!")
    lower = bus_time(w.events).lower_bound
    assert lower >= reply_end + 5.0 - 1e-9  # the start, then the whole 5 s ttt


def test_a_break_still_ends_an_m_measurements_wait():
    """A break aborts ``aM!`` (R-4.4.5.1-01): what the tool waits after it is its own choice
    when nothing it sends next needs ttt to be over (here another measurement)."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0M!").pause(9e-3).send(DUT, "00053\r\n")
    reply_end = w.t
    w.pause(0.05).brk().pause(5.2).brk().pause(9e-3).send(TOOL, "0M!")
    lower = bus_time(w.events).lower_bound
    assert lower < reply_end + 0.05 + 2 * (13e-3 + MARKING_AFTER_BREAK) + 9e-3 + 4 * CHAR_TIME
    assert lower > reply_end  # the 50 ms up to the abort were the sensor's


def test_an_own_command_ends_a_concurrent_measurements_wait():
    """A command to the sensor itself aborts its concurrent measurement (R-4.4.7.1-01): the
    tool chose to end the wait there, and waiting out ttt afterwards is its own patience
    when its next command to the sensor needs no ttt (here ``aI!`` again)."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    w.pause(0.05).send(TOOL, "0I!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(5.2).brk().pause(9e-3).send(TOOL, "0I!")
    lower = bus_time(w.events).lower_bound
    assert lower < 1.0  # frames, delays and the 50 ms of ttt before 0I!, not the 5.2 s
    assert lower > 0.05


def test_data_asked_after_an_own_command_abort_counts_the_whole_ttt():
    """``aD0!`` sent once ttt ran out after ``aI!`` aborted ``aC!`` asks whether the data
    are gone (R-4.4.7.1-01): before ttt a sensor that ignored the abort answers as one that
    obeyed, so no recorder shows the abort sooner and the whole ttt is the verdict's."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    reply_end = w.t
    w.pause(0.05).send(TOOL, "0I!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(5.2).brk().pause(9e-3).send(TOOL, "0D0!")
    lower = bus_time(w.events).lower_bound
    assert lower >= reply_end + 5.0 - 1e-9  # the start, then the whole 5 s ttt
    assert lower < w.t - 0.1  # the 5 ms and more past ttt stay the tool's own


def test_data_asked_after_a_break_abort_counts_the_whole_ttt():
    """The same for ``aM!`` aborted by a break (R-4.4.5.1-01/02): silence, then ``aD0!``
    once ttt ran out."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0M!").pause(9e-3).send(DUT, "00053\r\n")
    reply_end = w.t
    w.pause(0.05).brk().pause(5.2).brk().pause(9e-3).send(TOOL, "0D0!")
    lower = bus_time(w.events).lower_bound
    assert lower >= reply_end + 5.0 - 1e-9
    assert lower < w.t - 0.1


def test_data_asked_before_ttt_ran_out_leaves_an_abort_the_tools_choice():
    """``aD0!`` right after the abort could show nothing ttt would: the wait stays cut."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    w.pause(0.05).send(TOOL, "0I!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(1.0).brk().pause(9e-3).send(TOOL, "0D0!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(4.2).brk().pause(9e-3).send(TOOL, "0D0!")  # not the next command after the abort
    assert bus_time(w.events).lower_bound < 1.0


def test_only_the_next_command_to_the_sensor_shows_an_abort_was_needed():
    """Another command to the sensor between the abort and ``aD0!`` (which a sensor might
    take as the abort) leaves the wait cut; a command to another address does not."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    w.pause(0.05).send(TOOL, "0I!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(1.0).brk().pause(9e-3).send(TOOL, "0!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(4.2).brk().pause(9e-3).send(TOOL, "0D0!")
    assert bus_time(w.events).lower_bound < 1.0
    w = Wire().brk().pause(9e-3).send(TOOL, "0C!").pause(9e-3).send(DUT, "000520\r\n")
    reply_end = w.t
    w.pause(0.05).send(TOOL, "0I!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(1.0).brk().pause(9e-3).send(TOOL, "1!")  # another sensor: no answer
    w.pause(4.2).brk().pause(9e-3).send(TOOL, "0D0!")
    assert bus_time(w.events).lower_bound >= reply_end + 5.0 - 1e-9


def test_a_concurrent_wait_at_another_address_is_not_ended_by_the_duts_commands():
    """On a shared line, ``1C!`` keeps running while the tool talks to sensor 0."""
    w = Wire().brk().pause(9e-3).send(TOOL, "1C!").pause(9e-3).send(DUT, "100320\r\n")
    reply_end = w.t
    w.pause(0.05).brk().pause(9e-3).send(TOOL, "0I!").pause(9e-3).send(DUT, "0\r\n")
    w.pause(3.2).brk().pause(9e-3).send(TOOL, "1D0!")
    assert bus_time(w.events).lower_bound >= reply_end + 3.0 - 1e-9


def test_the_uncounted_stretches_are_the_span_less_the_bound():
    """``uncounted`` gives where the wall beyond the bound went: here the 9 ms of marking
    after the break less the 8.33 ms it needs, the tool's 200 ms of patience after an
    unanswered command less the 16.67 ms a retry must wait, and the 300 ms it marked after
    a reply less the 7.5 ms the sensor may hold the line."""
    w = Wire().brk().pause(9e-3).send(TOOL, "0!").pause(0.2)
    w.send(TOOL, "0!").pause(9e-3).send(DUT, "0\r\n").pause(0.3)
    w.send(TOOL, "0!")
    figures = bus_time(w.events)
    holes = uncounted(w.events)
    assert [round(b - a, 6) for a, b in holes] == [
        round(9e-3 - MARKING_AFTER_BREAK, 6),
        round(0.2 - RETRY_MIN, 6),
        round(0.3 - RELEASE_LINE, 6),
    ]
    assert sum(b - a for a, b in holes) == pytest.approx(figures.span - figures.lower_bound)
    assert uncounted([]) == []
