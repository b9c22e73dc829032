"""Kernel receive stamps are wall-clock time; the links turn them into perf_counter time with
the offset between the two clocks. Read once back to back, a thread descheduled between the
two reads (a loaded host) shifted that byte's stamp by the whole stall."""

from __future__ import annotations

import time

from conformance.links import kernel_stamps


def _clocks(monkeypatch, perf: list[int], wall: list[int]) -> None:
    perf_it, wall_it = iter(perf), iter(wall)
    monkeypatch.setattr(time, "perf_counter_ns", lambda: next(perf_it))
    monkeypatch.setattr(time, "time_ns", lambda: next(wall_it))


def test_a_stall_between_the_two_clock_reads_does_not_shift_the_offset(monkeypatch):
    """True offset 1,000,000,000 ns. The first bracket has a 40 ms stall after the wall read
    (the order of reads: perf, wall, perf); the second is tight."""
    stall = 40_000_000
    perf = [100, 100 + stall, 200_000_000, 200_000_010]
    wall = [1_000_000_100, 1_200_000_005]
    _clocks(monkeypatch, perf, wall)
    offset = kernel_stamps._clock_offset_ns()
    assert abs(offset - 1_000_000_000) <= 10


def test_a_tight_first_bracket_is_taken_at_once(monkeypatch):
    _clocks(monkeypatch, [500, 520], [2_000_000_510])
    assert kernel_stamps._clock_offset_ns() == 2_000_000_000


def test_on_this_machine_the_offset_is_stable_to_well_under_a_millisecond():
    offsets = [kernel_stamps._clock_offset_ns() for _ in range(200)]
    assert max(offsets) - min(offsets) < 1_000_000


def test_a_served_lines_clock_pairs_with_the_wall_clock_across_a_stall(monkeypatch):
    """The emulator server's reader pairs its line clock (s) with the wall clock the same
    way: a 40 ms stall between the first two reads does not shift the pair."""
    line = iter([10.0, 10.040, 11.0, 11.00001])
    monkeypatch.setattr(time, "time_ns", iter([5_000_000_000, 6_000_005_000]).__next__)
    now, wall = kernel_stamps.bracketed_wall(line.__next__, 50e-6)
    assert abs((wall / 1e9 - now) - (5.0 - 10.0)) < 1e-5
