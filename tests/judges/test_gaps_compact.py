"""R-7.0-12 / R-7.0-01 in memory that does not grow a tuple per gap (issue 22: an hour of a
busy bus is 25,000 character gaps a sensor). ``timing.Observed`` holds each observation as
three array entries (its object's index, its reply's index, the character's index), and
``wire.judge_gaps`` over a plain list of segments (a passive run's) cuts and judges their
gaps :data:`~conformance.judges.wire.SEGMENTS_AT_ONCE` segments at a time through
``ReplyGaps`` instead of listing every gap first. Both give the one-pass findings, detail for
detail; the memory figures fail on the tree before (a list of ``(measured, False, place)``
tuples: ~130 bytes a gap; every gap listed twice over by ``judge_gaps``: ~4 MB traced for
the 18,000 gaps below)."""

from __future__ import annotations

import random
import tracemalloc
from dataclasses import asdict

import pytest

from conformance.judges import wire
from conformance.judges.timing import Observed, StampUncertainty
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1
from conformance.view.runs import Segment, Segments

REPLY = "0+1.23-45.6+7.891\r\n"  # the busy bus's reply: 18 gaps


def _segments(n: int, rng: random.Random | None = None) -> list[Segment]:
    """``n`` replies to ``aD0!``; with ``rng`` each gap drawn from values around the limit
    and the tolerance band (FAIL, maybe, sure), else every gap 0.1 ms."""
    segs = []
    t = 0.0
    for k in range(n):
        reply = []
        for c in REPLY:
            reply.append(Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
            gap = 0.1e-3 if rng is None else rng.choice([0.0, 0.1e-3, 1.5e-3, 1.7e-3, 2.5e-3])
            t += CHAR_TIME + gap
        segs.append(Segment(None, [], reply, text=f"{k % 10}D0!"))
        t += 0.2
    return segs


def _traced_peak(make) -> tuple[object, int]:
    """``make()`` and the most memory traced above what was held before it (bytes)."""
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        before = tracemalloc.get_traced_memory()[0]
        made = make()
        return made, tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize(
    "stamps",
    [StampUncertainty(1e-6), StampUncertainty(0.1e-3, local=lambda a, b: 0.3e-3 if a < 5 else 0)],
    ids=["capture", "host-stamped"],
)
@pytest.mark.parametrize("seed", [1, 2])
def test_gaps_judged_in_parts_are_the_one_pass_findings(stamps, seed):
    segs = _segments(3 * wire.SEGMENTS_AT_ONCE + 5, random.Random(seed))
    parts = [asdict(f) for f in wire.judge_gaps(segs, stamps)]
    whole = [asdict(f) for f in wire.judge_gaps(Segments(segs), stamps)]  # one pass, cached
    assert parts == whole
    assert whole[0]["verdict"] != "PASS" and whole[1]["verdict"] != "PASS"  # both rules hit


def test_observed_holds_an_observation_in_a_few_bytes():
    segs = _segments(1000)
    gaps = wire._cut_gaps(segs)
    assert len(gaps) == 18_000
    observed, traced = _traced_peak(lambda: wire._observe_gaps_alike(gaps, 1e-6))
    assert type(observed) is Observed and len(observed) == 18_000
    assert traced / len(observed) < 30, f"{traced / len(observed):.0f} bytes an observation"
    # read back, the places are those of the gaps, the objects one per distinct value
    assert [o[2] for o in observed] == [g[4] for g in gaps]
    assert len(observed.distinct) == len({(g[0], g[1]) for g in gaps})


def test_judging_a_plain_list_lists_no_gap_of_the_whole():
    segs = _segments(1000)
    found, traced = _traced_peak(lambda: wire.judge_gaps(segs, 1e-6))
    assert found[0].observed == 18_000 or "18000 character gaps" in found[0].detail
    assert traced < 600_000, f"{traced / 1e6:.2f} MB traced judging 18,000 gaps"
