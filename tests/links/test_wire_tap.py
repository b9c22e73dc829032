"""``benchmarks/wire_tap.py`` (``bus_efficiency.py --wire``): the tool's events put on the
line's own clock from an ``emulate --tap`` listener, the bound there, and the adapter floor
(what a free-running latency timer's delivery of each answered reply's last character adds
past the 7.5 ms the bound gives the sensor)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from conformance.links.bus_time import bus_time
from conformance.protocol.timing import RELEASE_LINE
from conformance.transcript import DUT, TOOL, Event, EventKind
from tests.links.test_bus_time import Wire
from tests.support.paths import benchmark

TICK = 16e-3
PHASE = 5.3e-3  # where the latency timer ticks on the tap's clock, modulo TICK
OFFSET = 100.0  # the tool's clock less the tap's


def tap_module():
    return benchmark("wire_tap")


def _delivered(end: float) -> float:
    return PHASE + math.ceil((end - PHASE) / TICK) * TICK


def _line() -> list[Event]:
    """The wire: host-timed breaks, commands, replies answered after various turnarounds."""
    w = Wire().pause(1.0)
    for turnaround in (9e-3, 20e-3, 12e-3, 30e-3):
        w.brk().pause(9e-3).send(TOOL, "0I!").pause(9.4e-3).send(DUT, "013X\r\n")
        w.pause(turnaround).send(TOOL, "0!").pause(9.4e-3).send(DUT, "0\r\n").pause(0.2)
    return [
        replace(e, text="break held 13 ms (timed by the host)") if e.kind is EventKind.BREAK else e
        for e in w.events
    ]


def _as_the_tool_stamped(line: list[Event]) -> list[Event]:
    """The tool's transcript: its own clock; each reply character stamped where the latency
    timer delivered it."""
    out = []
    for e in line:
        end = _delivered(e.end) if e.origin == DUT else e.end
        out.append(replace(e, start=end - e.duration + OFFSET, end=end + OFFSET))
    return out


def _heard(line: list[Event], module) -> list[tuple[float, int]]:
    return [
        (e.start + module.BREAK_HEARD, 0) if e.kind is EventKind.BREAK else (e.end, e.wire)
        for e in line
    ]


def test_the_tool_events_go_back_to_the_line_and_the_bound_is_the_line_s():
    module = tap_module()
    line = _line()
    figures = module.wire_figures(_as_the_tool_stamped(line), _heard(line, module), TICK)
    assert figures.matched == len(line) and figures.unmatched == 0
    assert figures.bound == pytest.approx(bus_time(line).lower_bound)
    assert figures.span == pytest.approx(line[-1].end - line[0].start)


def _added(line: list[Event], release_from_delivery: bool) -> float:
    """What the adapter's delivery adds after each answered reply on ``line``: past the 7.5
    ms the bound gives the sensor, counted from the stop bit (the adapter floor) or from
    the delivery (the delivery floor), up to the next transmission."""
    added = 0.0
    for a, b in zip(line, line[1:], strict=False):
        if a.origin == DUT and b.origin == TOOL:
            late = _delivered(a.end) - a.end
            held = RELEASE_LINE + late if release_from_delivery else late
            added += max(0.0, min(held, b.start - a.end) - RELEASE_LINE)
    return added


def test_the_adapter_floor_adds_the_delivery_past_the_release_time():
    module = tap_module()
    line = _line()
    figures = module.wire_figures(_as_the_tool_stamped(line), _heard(line, module), TICK)
    added = _added(line, release_from_delivery=False)
    assert added > 0  # some replies came later than 7.5 ms
    assert figures.adapter_floor - figures.bound == pytest.approx(added, abs=2e-4)
    assert 0.0 <= figures.lateness_worst <= TICK


def test_the_delivery_floor_counts_the_sensor_s_release_from_the_delivery():
    """A recorder that sees the line only through the adapter gives the sensor its 7.5 ms
    from the delivery: the whole lateness is added after each answered reply (up to the
    next transmission), not only what passes 7.5 ms."""
    module = tap_module()
    line = _line()
    figures = module.wire_figures(_as_the_tool_stamped(line), _heard(line, module), TICK)
    added = _added(line, release_from_delivery=True)
    # each turnaround's lateness is off by up to half a bin of the fitted phase
    half_bin = TICK / module.PHASE_BINS / 2
    assert figures.delivery_floor - figures.bound == pytest.approx(added, abs=8 * half_bin)
    assert figures.delivery_floor > figures.adapter_floor


def test_without_a_latency_timer_the_floor_is_the_bound():
    module = tap_module()
    line = _line()
    figures = module.wire_figures(_as_the_tool_stamped(line), _heard(line, module))
    assert figures.adapter_floor == figures.bound and figures.turnarounds == 0
    assert figures.delivery_floor == figures.bound


def test_alignment_skips_what_only_one_side_has():
    module = tap_module()
    line = _line()
    heard = _heard(line, module)
    heard.insert(3, (heard[2][0] + 1e-3, 0x55))  # a byte of the bench probe, not in the run
    pairs = module.align(line, heard)
    assert [e for e, _ in pairs] == line
