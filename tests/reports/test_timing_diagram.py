"""The index that finds the exchange behind a whole-run timing finding picks what a scan of
every segment's intervals, in recording order, would pick (the first segment nearest)."""

from __future__ import annotations

from array import array

from hypothesis import given
from hypothesis import strategies as st

from conformance.reports.timing_diagram import MeasureIndex

# few distinct values, so that ties (equal values, equal distances either side) are common
value = st.sampled_from([-2.5, -0.0, 0.0, 1.0, 7.5, 8.33, 9.0, 10.5, 15.4, 16.0])


def scan(per_segment: list[list[float]], target: float) -> int | None:
    """The scan the index replaces: the first segment whose interval is nearest."""
    best, distance = None, float("inf")
    for i, measures in enumerate(per_segment):
        for m in measures:
            if abs(m - target) < distance:
                best, distance = i, abs(m - target)
    return best


@given(st.lists(st.lists(value, max_size=4), max_size=12), st.floats(-5, 20) | value)
def test_the_index_picks_what_a_scan_picks(per_segment: list[list[float]], target: float):
    assert MeasureIndex(measures=per_segment).nearest(target) == scan(per_segment, target)


def test_equal_values_and_equally_near_distinct_values_give_the_first_segment():
    """Runs of equal values (a simulated run's gaps) answer with their first segment, and
    distinct values whose distances to the target round equal are all weighed."""
    gaps = [[8.333] * 3, [16.666, 8.333], [8.333], [16.666]]
    for target in (8.0, 8.333, 12.4995, 16.666, 20.0, 0.0):
        assert MeasureIndex(measures=gaps).nearest(target) == scan(gaps, target)
    a, b = 1.0, 1.0 + 2**-52  # distinct, yet 1e17 - a == 1e17 - b
    far = 1e17
    assert a != b and far - a == far - b
    for per_segment in ([[b], [a]], [[a], [b]], [[b, a], [a]], [[a], [a], [b]]):
        assert MeasureIndex(measures=per_segment).nearest(far) == scan(per_segment, far)
        assert MeasureIndex(measures=per_segment).nearest(-far) == scan(per_segment, -far)


def test_an_index_of_any_length_keeps_each_distinct_value_once():
    """A simulated run's 33,000 intervals are a few dozen values: the index holds those, each
    with its first segment (it kept and sorted every interval below 50,000, or without numpy
    loaded: 16-20 ms of the page's renderer); with a NaN, every interval, as the sort gave."""
    index = MeasureIndex(measures=[[8.33] * 3, [8.33, 1.0], [-0.0, 0.0]])
    assert list(index.values) == [-0.0, 1.0, 8.33] and list(index.owners) == [2, 1, 0]
    assert str(index.values[0]) == "-0.0"  # the first spelling of the equal zeros
    nan = float("nan")
    with_nan = MeasureIndex(measures=[[8.33, nan], [8.33]])
    assert len(with_nan.values) == 3 and sorted(with_nan.owners) == [0, 0, 1]


def test_no_interval_no_segment():
    assert MeasureIndex(measures=[[], []]).nearest(8.0) is None
    assert MeasureIndex(measures=[[], [9.0]]).nearest(8.0) == 1


def first_of_runs(index: MeasureIndex) -> tuple[list[float], list[int]]:
    """The index's values and owners with each run of equal values kept as its first."""
    values: list[float] = []
    owners: list[int] = []
    for v, o in zip(index.values, index.owners, strict=True):
        if not values or v != values[-1]:
            values.append(v)
            owners.append(o)
    return values, owners


@given(
    st.lists(st.lists(value, max_size=4), max_size=80),  # past numpy's insertion sort
    st.lists(st.floats(-5, 20) | value, max_size=6),
)
def test_the_distinct_values_order_the_index_as_the_sort_does(
    per_segment: list[list[float]], targets: list[float]
):
    """The index keeps each distinct value once with its first segment: the arrays of
    Python's stable sort of every interval, to the sign of a zero, with each run of equal
    values kept as its first only; both answer every target as the scan does."""
    plain = MeasureIndex(measures=per_segment, every_interval=True)
    fast = MeasureIndex(measures=per_segment)
    values, owners = first_of_runs(plain)
    assert fast.values.tobytes() == array("d", values).tobytes()
    assert list(fast.owners) == owners
    assert len(plain.values) == sum(map(len, per_segment))
    for target in targets:
        assert fast.nearest(target) == plain.nearest(target) == scan(per_segment, target)


def test_a_long_index_imports_no_numpy_for_its_order():
    """A long index loads no numpy for its order: a simulated run of 145,000 intervals
    (sim://?faults=wrong-crc) paid more for the import than numpy's order saved. Both orders
    are the same (the test above)."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from conformance.reports.timing_diagram import MeasureIndex\n"
        "segments = [[float(i % 97), float(i % 13)] for i in range(50_000)]\n"
        "MeasureIndex(measures=segments)\n"
        "print('numpy' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=True
    )
    assert done.stdout.strip() == "False", done.stdout + done.stderr


def test_a_long_index_is_built_without_an_array_of_every_interval():
    """Issue 22: the index of a long recording was the peak of its passive judgement (every
    interval in two arrays, 16 bytes each, and numpy's argsort of them: 9.3 MB above what was
    held at 30 minutes of a busy capture). It is read as the segments come now: 200,000
    intervals of 1,003 distinct values peak at the few kept, not at the intervals (3.2 MB of
    arrays and more on the tree before, 689a849). The same index (the tests above)."""
    import tracemalloc

    per_segment = [[float(i % 1000), float(i % 7), 8.33, float(-(i % 3))] for i in range(50_000)]
    tracemalloc.start()
    try:
        before, _ = tracemalloc.get_traced_memory()
        index = MeasureIndex(measures=per_segment)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(index.values) == 1003 and index.nearest(999.2) == 999
    assert peak - before < 1_000_000, f"{(peak - before) / 1e6:.1f} MB at the peak"
