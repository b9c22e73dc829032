"""TimingMeter.between answers from an index of the taints and a cache of the spreads (a
whole-run judge asks it once a gap, 3*10^4 times on a full run): the same figure, to the
bit, as scanning every taint and spread, for taints and spreads that grow between asks."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.links.meter import MIN_FOR_OUTLIERS, TimingMeter, _worst_taint

times = st.floats(min_value=0.0, max_value=300.0, allow_nan=False)
errors = st.floats(min_value=0.0, max_value=0.05, allow_nan=False)
spans = st.tuples(times, st.floats(min_value=-0.01, max_value=2.0, allow_nan=False), errors)


def _scanned(meter: TimingMeter, start: float, end: float) -> float:
    """between() as it was: every taint and spread looked at on every ask."""
    floor = 0.25e-3 if meter.echo else meter.declared
    values = sorted(v for _s, _e, v in meter.spreads)
    if not values:
        regular = 0.0
    elif len(values) < MIN_FOR_OUTLIERS:
        regular = values[-1]
    else:
        regular = max(v for v in values if v <= meter._outlier_cut(values))
    if not meter.kernel_stamps:
        regular = max(regular, meter.reader_lag.value)
    u = _worst_taint(meter.taints, start, end, max(floor, regular, meter.widen_to))
    if len(values) >= MIN_FOR_OUTLIERS:
        cut = meter._outlier_cut(values)
        for s0, s1, v in meter.spreads:
            if v > cut and s0 <= end and start <= s1:
                u = max(u, v)
    return u


@settings(max_examples=150, deadline=None)
@given(
    taints=st.lists(spans, max_size=60),
    spreads=st.lists(spans, max_size=80),
    asks=st.lists(st.tuples(times, st.floats(0.0, 1.0, allow_nan=False)), min_size=1, max_size=20),
    echo=st.booleans(),
)
def test_between_is_the_scan_of_every_taint_and_spread(taints, spreads, asks, echo):
    meter = TimingMeter(5e-3, echo=echo)
    for i, (start, length) in enumerate(asks):
        # the lists grow between asks, as the reader thread adds to them during a run
        for s, d, e in taints[i * 3 : i * 3 + 3]:
            meter.taint(s, s + d, e, "test")
        for s, d, e in spreads[i * 4 : i * 4 + 4]:
            meter.spread(s, s + d, e, "test")
        end = start + length
        assert meter.between(start, end) == _scanned(meter, start, end)
        assert meter.between(end, end) == _scanned(meter, end, end)


def test_a_taint_that_ends_where_the_measurement_starts_touches_it():
    meter = TimingMeter(1e-3)
    meter.taint(10.0, 10.5, 0.02, "stall")
    meter.taint(0.0, 0.1, 0.03, "stall")
    assert meter.between(10.5, 11.0) == 0.02
    assert meter.between(10.6, 11.0) == 1e-3
    assert meter.between(9.0, 10.0) == 0.02
    assert meter.between(0.1, 0.1) == 0.03
