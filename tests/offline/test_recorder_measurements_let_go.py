"""The recorder pass judges each measurement once it is over and lets it go (issue 22,
memory27): :class:`~conformance.judges.recorder.measurements.ObservedMeasurements` hands
each one out (:meth:`finished`, in the order begun) to the measurement rules' folds
(:class:`MeasureWaits`, :class:`ConcurrentWaits`, :class:`DataCollection`,
:class:`HighVolume`), whose findings must be the whole-list functions' over
:func:`observed_measurements` of the whole view, and what the pass holds of the
measurements must not grow with the recording (a measuring bus's held every event of it,
~0.6 MB a minute).

The recording: ``benchmarks/measuring_bus.py``'s cycle (a measurement waiting for its
service request, an immediate one, a CRC one, a concurrent round with one aborted, aHB!
and aHA! read past aD9!, a retried sensor), laid end to end."""

from __future__ import annotations

from types import ModuleType
from typing import TypeVar

import pytest

from conformance.judges.recorder.breaks import BreakRules
from conformance.judges.recorder.collection import (
    DataCollection,
    HighVolume,
    judge_data_collection,
    judge_high_volume,
)
from conformance.judges.recorder.measurements import (
    ObservedMeasurement,
    ObservedMeasurements,
    observed_measurements,
)
from conformance.judges.recorder.retries import Retries
from conformance.judges.recorder.waits import (
    ConcurrentWaits,
    MeasureWaits,
    judge_concurrent_waits,
    judge_measure_waits,
)
from conformance.judges.timing import judge_window
from conformance.links.host_stall import Stall
from conformance.offline import recorder_windows
from conformance.offline.recorder_windows import judge_windows
from conformance.protocol.commands import CONCURRENT_KINDS, Kind
from conformance.transcript import Event, escape
from conformance.verdicts import Verdict
from conformance.view.segments import read_view
from conformance.view.windows import stream_windows
from tests.support.paths import benchmark
from tests.support.windowed_judges import at_every_break

U = 1e-6  # the capture's 1 MHz stamps


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return benchmark("measuring_bus")


@pytest.fixture(scope="module")
def bus(bench: ModuleType) -> list[Event]:
    """Three cycles of the measuring bus."""
    _, length = bench._cycle()
    return bench.measuring_bus(3 * length + 0.1)


@pytest.fixture(scope="module")
def whole(bus: list[Event]) -> list[ObservedMeasurement]:
    taken = observed_measurements(read_view(bus), U)
    kinds = {m.kind for m in taken}
    assert {Kind.MEASURE, Kind.CONCURRENT, Kind.HIGH_VOLUME_ASCII} <= kinds
    assert Kind.HIGH_VOLUME_BINARY in kinds and len(taken) >= 3 * 8
    return taken


def _windows(bus: list[Event]) -> list[list[Event]]:
    return list(stream_windows(iter(bus), uncertainty=U))


def test_the_folds_given_one_at_a_time_are_the_list_functions(whole):
    """Each fold given the measurements one by one, its findings asked twice: the whole-list
    function's (itself those folds) and, for the waits, a finding per measurement as
    before (:func:`judge_window`), which :class:`~conformance.judges.recorder.waits.Waits`
    holds one object per distinct wait of."""
    waits, concurrent = MeasureWaits(U), ConcurrentWaits(U)
    collection, high_volume = DataCollection(), HighVolume()
    for m in whole:
        for fold in (waits, concurrent, collection, high_volume):
            fold.take(m)
    for _ in range(2):
        assert waits.findings() == judge_measure_waits(whole, U)
        assert concurrent.findings() == judge_concurrent_waits(whole, U)
        assert collection.findings() == judge_data_collection(whole)
        for v14 in (True, False):
            assert high_volume.findings(v14) == judge_high_volume(whole, v14)
        assert high_volume.collections() == judge_high_volume(whole, True)[:2]
    assert concurrent.findings() == [_concurrent_as_before(whole)]
    assert len(concurrent.waits.judged) > len(set(map(id, concurrent.waits.judged)))
    by_rule = {f.requirement: f for f in waits.findings()}
    assert by_rule["R-4.4.5-04"].verdict is Verdict.PASS and by_rule["R-4.4.5-04"].observed >= 3


def _concurrent_as_before(taken: list[ObservedMeasurement]):
    """R-4.4.7-06 as it was judged before the fold: a :func:`judge_window` finding per
    measurement, combined."""
    from conformance.judges.recorder.common import combine

    found = [
        judge_window(
            "R-4.4.7-06",
            "first data command (or its break) after the concurrent reply",
            m.first_data.start - m.reply_end,
            U,
            low=float(m.ttt),
            evidence=[f"{m.first_data.at()} after {escape(m.start.text)} (ttt={m.ttt})"],
        )
        for m in taken
        if m.kind in CONCURRENT_KINDS and m.ttt and m.first_data is not None
    ]
    return combine("R-4.4.7-06", found, "concurrent wait")


@pytest.mark.parametrize("cut", ["stream", "every break"])
def test_the_recorder_pass_judges_the_measurements_as_the_list_functions(bus, whole, cut):
    """The pass over the windows (each measurement handed over once it is over, the last
    ones at the end): the list functions' findings over the whole view's measurements."""
    windows = _windows(bus) if cut == "stream" else at_every_break(bus)
    found = judge_windows(windows, U)
    assert found.measured == len(whole)
    assert found.measure_waits == judge_measure_waits(whole, U)
    assert found.concurrent_waits == judge_concurrent_waits(whole, U)
    assert found.data_collection == judge_data_collection(whole)
    assert found.high_volume == judge_high_volume(whole, False)[:2]


def test_measurements_are_handed_out_once_in_the_order_begun(bus, whole):
    """:meth:`finished` after each window and :meth:`rest` at the end give the whole view's
    measurements, each once, in the order begun; :meth:`measurements` (the list API) of a
    fold never asked gives them all."""
    taken, kept = ObservedMeasurements(U), ObservedMeasurements(U)
    handed: list[ObservedMeasurement] = []
    for window in _windows(bus):
        view = read_view(window)
        taken.add(view)
        kept.add(view)
        handed += taken.finished()
        assert taken.finished() == []
    handed += taken.rest()
    assert handed == whole == kept.measurements()
    assert taken.held == 0 and taken.rest() == [] and taken.measurements() == []


def _held_after_windows(events: list[Event], monkeypatch) -> tuple[int, int]:
    """The most measurements the recorder pass's :class:`ObservedMeasurements` held after a
    window's measurements were handed out, and how many it judged."""
    most: list[int] = []

    class Counting(ObservedMeasurements):
        def finished(self) -> list[ObservedMeasurement]:
            out = super().finished()
            most.append(self.held)
            return out

    monkeypatch.setattr(recorder_windows, "ObservedMeasurements", Counting)
    found = judge_windows(_windows(events), U)
    return max(most), found.measured


def test_the_recorder_pass_holds_no_finished_measurement(bench, monkeypatch):
    """A recording five times as long: the measurements held between windows do not grow
    (a cycle's at most: those still followed and the few over behind them), where every
    measurement of the recording was held before."""
    _, length = bench._cycle()
    short = bench.measuring_bus(4 * length + 0.1)
    long = bench.measuring_bus(20 * length + 0.1)
    held_short, measured_short = _held_after_windows(short, monkeypatch)
    held_long, measured_long = _held_after_windows(long, monkeypatch)
    assert measured_long == 5 * measured_short
    per_cycle = measured_short // 4
    assert held_long == held_short <= per_cycle


T = TypeVar("T")

#: a stall of the tool's host that no interval of the bus is near: the folds given it keep a
#: finding each (:func:`~conformance.judges.recorder.stalls.hold` leaves each as it is)
FAR = Stall(-10.0, -9.0, 1.0)


def _fed_both(held: T, each: T, bus: object) -> tuple[T, T]:
    """Both folds fed every window's view of ``bus``, in order."""
    for window in _windows(bus):
        view = read_view(window)
        held.add(view)  # type: ignore[attr-defined]
        each.add(view)  # type: ignore[attr-defined]
    return held, each


def test_the_break_rules_hold_an_object_per_distinct_interval(bus):
    """R-7.0-17 (a command to the same sensor without a break) and R-7.1-01 (aD0! after the
    service request) held as one object per distinct interval (and a break after a service
    request as its first PASS again) give the findings of a finding per command, which the
    fold still makes where noted stalls of the tool's host are (one here that no interval
    is near: :func:`~conformance.judges.recorder.stalls.hold` leaves each as it is)."""
    held, each = _fed_both(BreakRules(U), BreakRules(U, [FAR]), bus)
    assert held.findings() == each.findings()
    assert len(each.rule17) == len(set(map(id, each.rule17))) > 3
    assert len(held.rule17) == len(each.rule17) > len(set(map(id, held.rule17)))
    assert len(held.rule71) == len(each.rule71) > len(set(map(id, held.rule71)))
    rule17, rule71 = held.findings()
    assert rule17.verdict is Verdict.PASS and rule17.observed == len(held.rule17)
    assert rule71.verdict is Verdict.PASS and rule71.observed == len(held.rule71)


def test_the_retry_waits_hold_an_object_per_distinct_wait(bus):
    """R-7.2-02's retries after no reply (the sensor that answers only a retry) held as one
    object per distinct wait give the findings of a finding per retry, which the fold still
    makes where noted stalls are (one that no retry is near)."""
    held, each = _fed_both(Retries(U), Retries(U, [FAR]), bus)
    assert held.findings() == each.findings()
    waits, every = held._acc.window, each._acc.window
    assert len(every) == len(set(map(id, every))) >= 3
    assert len(waits) == len(every) > len(set(map(id, waits)))
    by_rule = {f.requirement: f for f in held.findings()}
    assert by_rule["R-7.2-02"].verdict is Verdict.PASS
    assert by_rule["R-7.2-02"].observed == len(waits)
