"""R-7.0-12 / R-7.0-01's gaps taken a run at a time (issue 22, matrix19): ``wire._GapsAlike.
add_segments`` takes each run's gaps as one list of values, grouped by value, and observes them
at once (``timing.Observed.observe_run``) instead of a tuple and a call per gap. It must give
what the one-gap-at-a-time path gives (``_cut_gaps`` into ``_GapsAlike.add`` and
``_ToleranceUse.add``): the same distinct objects in the same order, the same counts, the same
observation at every place, the same R-7.0-01 gaps in and maybe in the band, and the same
findings. The drawn segments hold what sends a run down the one-at-a-time path (a zero gap, a
negative zero, a NaN, multi-line text with its LFs) beside plain runs, later runs (service
requests, chatter after the reply) and repeated commands (their places shared)."""

from __future__ import annotations

import math
import random
from dataclasses import asdict

import pytest

from conformance.judges import wire
from conformance.judges.timing import StampUncertainty
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.runs import Segment, Segments

GAPS = [0.1e-3, 0.1e-3, 0.25e-3, 1.5e-3, 1.7e-3, 1.9e-3, 2.5e-3, 3e-3]
ODD = [0.0, -0.0, math.nan, -0.2e-3]


def _chars(text: str, t: float, rng: random.Random, odd: float) -> tuple[list[Event], float]:
    chars = []
    for c in text:
        chars.append(Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
        gap = rng.choice(ODD) if rng.random() < odd else rng.choice(GAPS)
        if c == "\n" and rng.random() < 0.5:
            gap = 0.05  # between lines of multi-line text (or a run's end elsewhere)
        t += CHAR_TIME + (0.0 if math.isnan(gap) else gap)
        if math.isnan(gap):  # a NaN stamp: the next character starts at NaN
            chars[-1] = Event(EventKind.CHAR, DUT, t, math.nan, wire=to_wire_7e1(ord(c)))
    return chars, t


def _segments(n: int, rng: random.Random, odd: float) -> list[Segment]:
    segs = []
    t = 0.0
    for k in range(n):
        kind = rng.choice(["plain", "plain", "later", "multiline", "empty"])
        text = f"{k % 3}D0!" if kind != "multiline" else f"{k % 3}IHA!"
        body = "0+1.23-45.6+7.891\r\n" if kind != "multiline" else "0\x02ab\r\ncd\r\n\x03"
        reply, t = _chars(body, t, rng, odd) if kind != "empty" else ([], t)
        later: list[Event] = []
        if kind == "later":
            t += 0.3
            later, t = _chars("0\r\n", t, rng, odd)
            t += 0.3
            more, t = _chars("0\r\n", t, rng, odd)
            later += more
        segs.append(Segment(None, [], reply, later=later, text=text))
        t += 0.2
    return segs


def _negative_zero(text: str) -> Segment:
    """A reply whose first gap is a negative zero (its second character starts at -0.0, the
    first ends at 0.0): judged apart each time, never grouped with a zero."""
    wire_of = [to_wire_7e1(ord(c)) for c in "0\r\n"]
    chars = [
        Event(EventKind.CHAR, DUT, -CHAR_TIME, 0.0, wire=wire_of[0]),
        Event(EventKind.CHAR, DUT, -0.0, CHAR_TIME, wire=wire_of[1]),
        Event(EventKind.CHAR, DUT, CHAR_TIME, 2 * CHAR_TIME, wire=wire_of[2]),
    ]
    return Segment(None, [], chars, text=text)


def _one_at_a_time(segs: list[Segment], base: float):
    alike, tolerance = wire._GapsAlike(base), wire._ToleranceUse(base)
    gaps = wire._cut_gaps(segs)
    alike.add(gaps)
    tolerance.add(gaps)
    return alike, tolerance


def _by_run(segs: list[Segment], base: float):
    alike, tolerance = wire._GapsAlike(base), wire._ToleranceUse(base)
    alike.add_segments(segs, tolerance)
    return alike, tolerance


def _same(x: float, y: float) -> bool:
    return (math.isnan(x) and math.isnan(y)) or (
        x == y and math.copysign(1, x) == math.copysign(1, y)
    )


@pytest.mark.parametrize("base", [0.0, 1e-6, 0.3e-3])
@pytest.mark.parametrize("odd", [0.0, 0.02])
@pytest.mark.parametrize("seed", range(4))
def test_gaps_by_run_are_the_gaps_one_at_a_time(seed, odd, base):
    segs = _segments(60, random.Random(seed), odd)
    if odd:
        segs[5:5] = [_negative_zero("0D0!"), _negative_zero("0D0!")]
    old, old_tol = _one_at_a_time(segs, base)
    new, new_tol = _by_run(segs, base)
    a, b = old.observed, new.observed
    assert len(a.distinct) == len(b.distinct) and a.counts == b.counts
    for m, n in zip(a.distinct, b.distinct, strict=True):
        assert _same(m.measured, n.measured) and m.evidence_lines == n.evidence_lines
        assert (m.uncertainty, m.verdict) == (n.uncertainty, n.verdict)
    assert list(a._picks) == list(b._picks) and [o[2] for o in a] == [o[2] for o in b]
    assert (old_tol.count, len(old_tol.sure), len(old_tol.maybe)) == (
        new_tol.count,
        len(new_tol.sure),
        len(new_tol.maybe),
    )
    assert (repr(old_tol.sure), repr(old_tol.maybe)) == (repr(new_tol.sure), repr(new_tol.maybe))
    assert a.counts and sum(a.counts) == len(a)


@pytest.mark.parametrize("seed", range(3))
def test_judge_gaps_findings_unchanged(seed):
    """A run's segments judged through ReplyGaps (one uncertainty for every gap) give the
    findings the observations kept for confirmation give (the path before, still that of a
    host-stamped link)."""
    segs = _segments(80, random.Random(seed), 0.02)
    stamps = StampUncertainty(1e-6)
    # compared as text: a NaN gap's figures are no equal to themselves as floats
    new = repr([asdict(f) for f in wire.judge_gaps(Segments(segs), stamps)])
    observed = wire._observe_gaps(Segments(segs), stamps)
    old_gap = wire.combine_local("R-7.0-12", observed, "character gap", real_time=False)
    old_tol = wire._judge_tolerance_use(wire._cut_gaps(segs), stamps.base)
    assert new == repr([asdict(old_gap), asdict(old_tol)])
    assert old_gap.verdict is not Verdict.PASS and old_tol.verdict is not Verdict.PASS
