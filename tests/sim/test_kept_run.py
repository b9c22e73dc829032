"""Issue 22, matrix round 12: the sim bus's run of a reply into a plain transcript keeps the
clock in a local while it makes the characters (``SimLink._kept_run``). A stop condition is
the one thing outside the loop that runs meanwhile: it must see the clock as the character
by character read left it, and what it does to the clock must stand. Every read, the clock
at every stop, the transcript: the same as frame by frame."""

from __future__ import annotations

import pytest

from conformance.links.base import LineEnd
from conformance.sim.bus import SimBus, SimLink

from .test_bus import _frame_by_frame, _Talker


def _reads(planned: bool, monkeypatch: pytest.MonkeyPatch, nudge: bool = False) -> list:
    if not planned:
        _frame_by_frame(monkeypatch)
    kept = []
    link = SimLink(SimBus([_Talker()]))
    clock = link.bus.clock
    found = []

    def until(got, n):  # noqa: ANN001, ANN202 - a StopCondition that reads the clock
        kept.append(clock.now)
        if nudge and len(got) == 2:
            clock.now += 2e-3  # and one that moves it: what it did stands
        return len(got) >= n

    for ahead, count, idle in [(0.05, 3, None), (0.2, 40, 0.004), (0.5, 1, 0.02), (1.0, 9, None)]:
        got = link.receive(link.now() + ahead, until=lambda g, n=count: until(g, n), idle=idle)
        found.append(([(e.start, e.end, e.wire) for e in got], link.now()))
    line = link.receive(link.now() + 1.0, until=LineEnd([], 5), idle=0.05)
    found.append(([(e.start, e.end) for e in line], link.now()))
    monkeypatch.undo()
    return [found, kept, list(link.transcript.events)]


def test_a_stop_condition_sees_the_clock_the_character_by_character_read_left(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    planned = _reads(True, monkeypatch)
    assert planned == _reads(False, monkeypatch)
    assert len(planned[1]) > 10  # the stop condition was asked, in runs


def test_what_a_stop_condition_does_to_the_clock_stands(monkeypatch: pytest.MonkeyPatch) -> None:
    nudged = _reads(True, monkeypatch, nudge=True)
    assert nudged == _reads(False, monkeypatch, nudge=True)
    assert nudged != _reads(True, monkeypatch)
