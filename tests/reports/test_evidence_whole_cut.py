"""A report's search of a whole recording (a finding's exchange, a whole-run case's worst
value) answers the same from the segments made as they are read (:class:`LazyCut`, what a
passive judgement now gives it, none held: issue 22) as from the whole run's held list
(:func:`transcript_segments`, what a run whose whole-run cases cut it gives it).

The traffic is a busy bus of ten sensors (every exchange alike, so a measured value is held
by many segments and the first must be taken) with some replies moved by a fraction of a
millisecond (values held by one segment only); the findings name commands, chains of them,
times, and measured values on, near and off the segments' intervals."""

from __future__ import annotations

import random
from dataclasses import replace
from itertools import pairwise

import pytest

from conformance.reports.evidence import Locator, _nearest_measured
from conformance.reports.timing_diagram import _measures, exchange_behind
from conformance.results import CaseRecord
from conformance.transcript import DUT, Event, Transcript
from conformance.verdicts import Finding, Verdict
from conformance.view.runs import LazyCut, transcript_segments, transcript_view, whole_cut
from tests.support.paths import benchmark


def _busy_bus(seconds: float) -> list[Event]:
    return benchmark("capture_decode").busy_bus(seconds)


def _events(seed: int) -> list[Event]:
    """The busy bus, a few of its replies moved late by up to 0.3 ms (the whole reply, so the
    bus keeps its order): the response start and the last gap before them change."""
    rng = random.Random(seed)
    out: list[Event] = []
    shift = 0.0
    for e in _busy_bus(3.0):
        if e.origin != DUT:
            shift = rng.choice([0.0, 0.0, 0.0, rng.uniform(0, 3e-4)])
            out.append(e)
        else:
            out.append(replace(e, start=e.start + shift, end=e.end + shift))
    return out


def _transcripts(events: list[Event]) -> tuple[Transcript, Transcript]:
    """The same events twice: one transcript whose whole-run segments are held (the list),
    one whose are not (the lazy cut)."""
    held, lazy = Transcript(events), Transcript(events)
    transcript_segments(held)
    assert not isinstance(whole_cut(held), LazyCut)
    assert isinstance(whole_cut(lazy), LazyCut)
    return held, lazy


def _findings(events: list[Event], rng: random.Random) -> list[Finding]:
    segs = transcript_segments(Transcript(events))
    found: list[Finding] = []
    for _ in range(60):
        k = rng.randrange(len(segs))
        seg, nxt = segs[k], segs[(k + 1) % len(segs)]
        ms = _measures(seg)
        how = rng.randrange(5)
        measured = rng.choice(ms) + rng.choice([0.0, 0.0, 0.01, 0.04, 0.06, 3.0]) if ms else None
        evidence: list[str] = []
        if how == 1:
            evidence = [f"reply to {seg.text}"]
        elif how == 2:
            evidence, measured = [f"{seg.text} {nxt.text}"], None  # a chain
        elif how == 3:
            evidence = [f"reply to {seg.text} at t={seg.command[0].start:.4f} s"]
        elif how == 4:
            evidence, measured = [f"reply to {seg.text}", f"then {nxt.text}"], None
        found.append(
            Finding("R-7.0-10", Verdict.FAIL, "measured", evidence=evidence, measured_ms=measured)
        )
    return found


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_finding_is_located_alike_either_way(seed: int):
    events = _events(seed)
    held, lazy = _transcripts(events)
    rng = random.Random(seed)
    for f in _findings(events, rng):
        record = CaseRecord("n", "n", ("R-7.0-10",), findings=[f])
        a = Locator(events, held).locate(f, record)
        b = Locator(events, lazy).locate(f, record)
        assert a == b, f
    assert "_segments" not in lazy.__dict__  # nothing made the whole list


@pytest.mark.parametrize("seed", [1, 2])
def test_the_nearest_measured_segment_is_the_first_either_way(seed: int):
    """The first segment (wire order) holding the interval nearest the target, with how
    near: the lazy cut's index against the scan of the list, on values held by many
    segments, by one, between two and off every one."""
    events = _events(seed)
    held = transcript_segments(Transcript(events))
    lazy = LazyCut(transcript_view(Transcript(events)).transmissions)
    rng = random.Random(seed)
    values = sorted({m for s in held for m in _measures(s)})
    between = [(a + b) / 2 for a, b in pairwise(values)]
    targets = values + between + [-5.0, 1e6]
    for target in rng.sample(targets, min(300, len(targets))) + [float("nan")]:
        a = _nearest_measured(held, target)
        b = _nearest_measured(lazy, target)
        assert (a is None) == (b is None)
        if a is not None and b is not None:
            assert held.index(a[1]) == [i for i, s in enumerate(held) if s == b[1]][0]
            assert a[0] == b[0] or (a[0] != a[0] and b[0] != b[0])


def test_the_exchange_behind_a_worst_value_is_drawn_alike_either_way():
    events = _events(4)
    held, lazy = _transcripts(events)
    rng = random.Random(4)
    for f in _findings(events, rng):
        if f.measured_ms is None:
            continue
        assert exchange_behind([f], held) == exchange_behind([f], lazy), f
    assert "_segments" not in lazy.__dict__
