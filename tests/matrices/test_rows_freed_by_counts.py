"""A matrix row's run is freed by reference counts when the row ends, and the collector runs
once a row (issue 22, live28): a FAIL's exception (pytest's ``CallInfo`` and the frames its
traceback holds) and an exploration's broken invariant (the exception ``run_plan`` raises)
held the whole run in reference cycles, which only a full collection frees, and the
collector walked those runs' 10^5 objects as survivors while the batch lasted
(:func:`conformance.gc_pace.one_row`)."""

from __future__ import annotations

import gc
import weakref
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from conformance import gc_pace, many_runs
from conformance.emulator import FAULTS
from conformance.matrices.roundtrip import row_through_capture
from conformance.matrices.sensor_matrix import (
    Item,
    fault_port,
    matrix_run,
    paced_row,
    run_rows,
)
from conformance.sensor.exploration_steps import run_plan


class _Node:
    """An object in a reference cycle of its own, seen through a weak reference."""

    def __init__(self) -> None:
        self.me = self


@pytest.fixture
def collector_on() -> Iterator[None]:
    was = gc.isenabled()
    gc.enable()
    try:
        yield
    finally:
        if not was:
            gc.disable()


def test_one_row_pauses_the_collector_and_collects_the_rows_cycles(collector_on):
    with gc_pace.one_row():
        assert not gc.isenabled()
        cycle = weakref.ref(_Node())
        assert cycle() is not None  # in a cycle: no count frees it
    assert gc.isenabled()
    assert cycle() is None


def test_one_row_leaves_a_collector_that_is_off_off():
    was = gc.isenabled()
    gc.disable()
    try:
        with gc_pace.one_row():
            cycle = weakref.ref(_Node())
        assert not gc.isenabled()
        assert cycle() is not None  # nothing collected: the process never collects
    finally:
        gc.collect()
        if was:
            gc.enable()


def test_what_outlives_a_row_is_frozen_only_beside_what_a_run_froze(collector_on):
    gc.collect()
    assert gc.get_freeze_count() == 0
    kept = []
    with gc_pace.one_row():
        kept.append(_Node())
    assert gc.get_freeze_count() == 0  # nothing frozen before: nothing would thaw it
    gc.freeze()  # as slow_down does at a run's start
    try:
        before = gc.get_freeze_count()
        with gc_pace.one_row():
            kept.append(_Node())
        assert gc.get_freeze_count() > before  # the row's survivor with them
    finally:
        gc.unfreeze()


def test_a_row_raising_still_has_the_collector_back(collector_on):
    def fails(item: int) -> int:
        raise ValueError(item)

    with pytest.raises(ValueError):
        paced_row(fails, 3)
    assert gc.isenabled()


def test_run_rows_makes_each_row_with_the_collector_paused(collector_on):
    assert run_rows([1, 2], lambda item: (item, gc.isenabled()), processes=1) == [
        (1, False),
        (2, False),
    ]
    assert gc.isenabled()


def test_run_plan_leaves_no_cycle_through_the_exception_it_raises():
    class Broken(Exception):
        pass

    class Machine:
        def step(self, name: str, arguments: dict) -> None:
            raise Broken(name)

        def teardown(self) -> None:
            pass

    gc.collect()
    was = gc.isenabled()
    gc.disable()
    try:
        caught: list[weakref.ref] = []
        try:
            run_plan(Machine, [(("a", {}),)], lambda: (Exception,), lambda: ())  # type: ignore[arg-type]
        except Broken as exc:
            caught.append(weakref.ref(exc))
        assert caught and caught[0]() is None  # freed by its count as the except ended
    finally:
        if was:
            gc.enable()


def _item(fault: str) -> Item:
    return (fault, tuple(FAULTS[fault].violates), "14", ())


def _batch_with_the_collector_off(work: Callable[[], None]) -> None:
    gc.collect()
    was = gc.isenabled()
    gc.disable()
    try:
        many_runs.judged_in_one_session(work)
    finally:
        if was:
            gc.enable()


def test_a_failing_live_run_in_a_batch_is_freed_by_counts(tmp_path: Path):
    """``wrong-reply-address`` FAILs many cases: with the collector off, nothing of its run
    outlives it, and what it leaves in cycles is a few objects, not its 10^4..10^5."""
    item = ("wrong-reply-address", (), "14", ())
    refs: list[weakref.ref] = []
    left: list[int] = []

    def one(name: str) -> None:
        run, lines = matrix_run(tmp_path / name, fault_port(item))
        assert any(r["verdict"] == "FAIL" for r in lines["requirements"])
        refs[:] = [weakref.ref(o) for o in (run, run.link, run.link.transcript)]

    def work() -> None:
        one("first")  # the session's and the process's first-use caches
        gc.collect()
        one("second")
        left.append(sum(r() is not None for r in refs))
        left.append(gc.collect())

    _batch_with_the_collector_off(work)
    still_held, in_cycles = left
    assert still_held == 0
    assert in_cycles < 200


@pytest.mark.matrix  # two rows through their captures: seconds
def test_a_row_through_its_capture_leaves_no_run_in_cycles():
    """``answers-old-address``'s replayed capture breaks an exploration invariant (the
    exception :func:`run_plan` raises) besides FAILing its rules."""
    left: list[int] = []

    def work() -> None:
        row_through_capture(_item("never-standby"))  # first-use caches
        gc.collect()
        row = row_through_capture(_item("answers-old-address"))
        left.append(gc.collect())
        assert row.exact and row.capture == ()

    _batch_with_the_collector_off(work)
    assert left[0] < 200
