"""``judges.timing.stable_order``: numpy's stable argsort (from ``NUMPY_FROM`` values, an
hour's recording) gives the order Python's stable sort gives, ties in index order, signed
zeros as equals, and a NaN among the values leaves the order to Python's sort."""

from __future__ import annotations

from array import array

from hypothesis import given
from hypothesis import strategies as st

from conformance.judges.timing import distribution, stable_order

value = st.sampled_from([-2.5, -0.0, 0.0, 1.0, 7.5, 8.33, 9.0, 1e-300]) | st.floats(
    -20, 20, allow_nan=False
)


@given(st.lists(value, max_size=120))  # past numpy's insertion sort for short runs (16)
def test_numpy_gives_the_order_of_the_sort(values: list[float]):
    a = array("d", values)
    plain = sorted(range(len(a)), key=a.__getitem__)
    assert list(stable_order(a, numpy_from=0)) == plain
    assert list(stable_order(a)) == plain  # below NUMPY_FROM: the sort itself


@given(st.lists(value, max_size=20), st.integers(0, 20))
def test_a_nan_leaves_the_order_to_the_sort(values: list[float], at: int):
    values.insert(min(at, len(values)), float("nan"))
    a = array("d", values)
    assert list(stable_order(a, numpy_from=0)) == sorted(range(len(a)), key=a.__getitem__)


def test_no_value_no_distribution():
    assert distribution([]) is None
