"""``Repeats``: a judge of many intervals holds one observation per distinct value (the
first interval of that value stands for the others), and :func:`combine` of the list with
that object repeated gives, field for field, distribution and evidence included, what one
object per interval gave (issue 22, bounded memory: the recorder run's R-7.0-13 gaps,
R-7.0-02 breaks and R-7.0-06 markings were its peak). A zero of the other sign, a NaN and
another uncertainty are other values."""

from __future__ import annotations

import json
import math

from hypothesis import given
from hypothesis import strategies as st

from conformance.judges.recorder.common import combine
from conformance.judges.timing import MeasuredAsJudged, MeasuredIn, Repeats, Window, distribution
from tests.judges.test_timing_measured_as_judged import WINDOWS, interval, uncertainty

# few values, many times each (the busy bus's gaps), with both zeros and a NaN
repeated = st.sampled_from([0.0, -0.0, 1e-4, 0.0016, 0.00167, 0.002, 0.0125, math.nan]) | interval


def with_repeats(name: str, values: list[float], us: list[float]) -> list[MeasuredAsJudged]:
    rid, what, low, high, tol = WINDOWS[name]
    window = Window(rid, what, low, high, tol)
    seen: Repeats[MeasuredAsJudged] = Repeats()
    return [
        seen.first(v, u) or seen.keep(MeasuredAsJudged(window, v, u, [f"at {i}"]))
        for i, (v, u) in enumerate(zip(values, us, strict=True))
    ]


def one_each(name: str, values: list[float], us: list[float]) -> list[MeasuredAsJudged]:
    rid, what, low, high, tol = WINDOWS[name]
    window = Window(rid, what, low, high, tol)
    pairs = enumerate(zip(values, us, strict=True))
    return [MeasuredAsJudged(window, v, u, [f"at {i}"]) for i, (v, u) in pairs]


@given(
    st.sampled_from(sorted(WINDOWS)),
    st.lists(st.tuples(repeated, uncertainty), max_size=60),
)
def test_repeated_observations_combine_as_one_each(name: str, pairs: list[tuple[float, float]]):
    values, us = [p[0] for p in pairs], [p[1] for p in pairs]
    kept, each = with_repeats(name, values, us), one_each(name, values, us)
    rid = WINDOWS[name][0]
    # as text: a NaN is written alike, never equal to itself
    assert _text(combine(rid, kept, name).to_json()) == _text(combine(rid, each, name).to_json())
    assert repr(distribution(kept)) == repr(distribution(each))


def _text(found: dict) -> str:
    return json.dumps(found, sort_keys=True)


def test_one_object_per_value_and_the_first_one():
    values = [0.0005, 0.0005, 0.002, 0.0005, 0.002, -0.0, 0.0, -0.0, math.nan, math.nan]
    kept = with_repeats("gap", values, [1e-6] * len(values))
    assert kept[1] is kept[0] and kept[3] is kept[0] and kept[4] is kept[2]
    assert kept[5] is not kept[6] and kept[7] is kept[5]  # -0.0 and 0.0 are two values
    assert kept[8] is not kept[9]  # a NaN equals nothing
    assert len({id(k) for k in kept}) == 6
    assert combine("R-7.0-13", kept, "gap").evidence == ["at 2"]  # the first of the worst
    other = with_repeats("gap", [0.0005, 0.0005], [1e-6, 5e-5])
    assert other[0] is not other[1]  # another uncertainty: another interval


def test_measured_in_keeps_its_first_place():
    class Where:
        def __init__(self, name: str) -> None:
            self.name = name

        def at(self) -> str:
            return self.name

    window = Window("R-7.0-13", "marking between command characters", None, 0.00166, 0.0)
    seen: Repeats[MeasuredIn] = Repeats()
    kept = [
        seen.first(g, 0.0) or seen.keep(MeasuredIn(window, g, 0.0, Where(f"#{i}")))
        for i, g in enumerate([0.003, 0.001, 0.003])
    ]
    found = combine("R-7.0-13", kept, "gap")
    assert found.verdict.name == "FAIL" and found.evidence == ["in #0"] and found.observed == 3
