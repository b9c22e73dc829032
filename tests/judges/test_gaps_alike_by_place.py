"""R-7.0-12's gaps grouped as they are made (issue 22, matrix14): ``wire._GapsAlike`` finds a
gap judged before by its place's own dict, looked up when the place changes, instead of a
``(gap, where)`` key tuple made and hashed per gap. The observations, the distinct gaps and
their counts are those of the tuple-keyed grouping it replaces (kept below as the reference),
for gap sequences given a part at a time (as ``ReplyGaps`` gives windows) with ties, signed
zeros, NaN, places that come back after another, and equal places that are other objects."""

from __future__ import annotations

import math
from copy import copy
from math import copysign

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.judges import wire
from conformance.judges.timing import Measured, Observed

gap_values = st.sampled_from(
    [0.0, -0.0, math.nan, 0.3e-3, 1.66e-3, 1.7e-3, 1.9e-3, 2.06e-3, 2.5e-3, -1e-3]
) | st.floats(-1e-3, 3e-3, allow_nan=False)
# equal texts made apart (not interned) as well as one object: each segment makes its own
wheres = st.sampled_from(["0D0!", "0M!", "1D0!"]).flatmap(
    lambda text: st.sampled_from([f"in reply to {text}", "".join(["in reply to ", text])])
)


@st.composite
def gap_parts(draw):
    """Gaps as ``_cut_gaps`` gives them, drawn from few values so that many tie, cut into
    parts (the windows of a windowed judge)."""
    pool = draw(st.lists(st.tuples(gap_values, wheres), min_size=1, max_size=8))
    picks = draw(st.lists(st.integers(0, len(pool) - 1), min_size=0, max_size=300))
    gaps = [(pool[i][0], pool[i][1], None, None, ("0D0!", "0+1", k)) for k, i in enumerate(picks)]
    cuts = sorted(draw(st.lists(st.integers(0, len(gaps)), max_size=4)))
    return [gaps[a:b] for a, b in zip([0, *cuts], [*cuts, len(gaps)], strict=True)]


class _TupleKeyed(wire._GapsAlike):
    """The grouping before this round: a ``(gap, where)`` key per gap (held as
    :class:`~conformance.judges.timing.Observed` now holds its observations)."""

    def __init__(self, base: float) -> None:
        super().__init__(base)
        self.judged = {}

    def add(self, gaps) -> None:
        base, judged, observed = self.base, self.judged, self.observed
        distinct, counts = observed.distinct, observed.counts
        observe, new, once = observed.observe, distinct.append, counts.append
        for gap, where, _a, _b, place in gaps:
            if not gap and copysign(1.0, gap) < 0:
                observe(len(distinct), place)
                new(Measured(wire.GAP_WINDOW, gap, base, [where]))
                once(1)
                continue
            i = judged.get((gap, where))
            if i is None:
                i = judged[(gap, where)] = len(distinct)
                new(Measured(wire.GAP_WINDOW, gap, base, [where]))
                once(1)
            else:
                counts[i] += 1
            observe(i, place)


def _said(m: Measured) -> tuple:
    """What a Measured holds (NaN as its text: ``nan != nan``)."""
    return tuple(repr(getattr(m, name, None)) for name in Measured.__slots__)


def _grouped(kind: type[wire._GapsAlike], parts, base: float) -> Observed:
    alike = kind(base)
    for part in parts:
        alike.add(part)
    return alike.observed


@settings(max_examples=400, deadline=None)
@given(gap_parts(), st.sampled_from([0.0, 1e-5, 0.4e-3]))
def test_grouped_by_place_as_by_key_tuple(parts, base):
    new = _grouped(wire._GapsAlike, parts, base)
    old = _grouped(_TupleKeyed, parts, base)
    assert [_said(m) for m in new.distinct] == [_said(m) for m in old.distinct]
    assert new.counts == old.counts
    # each observation is the same distinct gap (by its index), flag and place
    index_new = {id(m): i for i, m in enumerate(new.distinct)}
    index_old = {id(m): i for i, m in enumerate(old.distinct)}
    assert [(index_new[id(m)], f, p) for m, f, p in new] == [
        (index_old[id(m)], f, p) for m, f, p in old
    ]


def test_a_place_that_comes_back_finds_its_gaps():
    """A place left and come back to (another object, equal) finds the gaps judged there."""
    first, other = "in reply to 0D0!", "in reply to 0M!"
    again = "".join(["in reply to ", "0D0!"])
    assert again == first and again is not first
    gaps = [
        (1e-3, first, None, None, ("0D0!", "0+1", 0)),
        (1e-3, other, None, None, ("0M!", "0", 0)),
    ]
    gaps += [
        (1e-3, again, None, None, ("0D0!", "0+1", 1)),
        (copy(-0.0), again, None, None, ("0D0!", "0+1", 2)),
    ]
    observed = _grouped(wire._GapsAlike, [gaps], 0.0)
    assert observed.counts == [2, 1, 1]  # first and again one gap; -0.0 judged apart
    assert observed[2][0] is observed[0][0]
