"""The Ctrl-C guard in-process: an interrupt that lands where Python cannot raise it (a
finalizer, a gc callback) is recorded silently and acted on at the next case boundary."""

from __future__ import annotations

import gc
import signal
import sys

import pytest

from conformance.interrupts import InterruptGuard


class _SignalsInFinalizer:
    def __del__(self) -> None:
        signal.raise_signal(signal.SIGINT)


@pytest.fixture
def guard(monkeypatch):
    # the tool runs its cases with pytest's unraisable plugin off: Python's own hook prints
    monkeypatch.setattr(sys, "unraisablehook", sys.__unraisablehook__)
    g = InterruptGuard()
    g.install()
    try:
        yield g
    finally:
        g.uninstall()


def test_interrupt_inside_a_finalizer_is_not_printed_and_stops_at_the_next_boundary(guard, capsys):
    with guard.armed():
        _SignalsInFinalizer()  # dropped at once: __del__ runs, the handler raises inside it
    assert guard.requested
    assert "Traceback" not in capsys.readouterr().err
    with pytest.raises(KeyboardInterrupt), guard.armed():
        pass
    assert guard.close() is True


def test_interrupt_inside_a_gc_callback_is_not_printed(guard, capsys):
    def callback(phase: str, info: dict) -> None:
        if phase == "start":
            signal.raise_signal(signal.SIGINT)

    gc.callbacks.append(callback)
    try:
        with guard.armed():
            gc.collect()
    finally:
        gc.callbacks.remove(callback)
    assert guard.requested
    assert "Traceback" not in capsys.readouterr().err


def test_other_unraisables_still_reach_the_previous_hook(guard):
    seen = []
    guard._previous_unraisable = seen.append

    class Raises:
        def __del__(self) -> None:
            raise ValueError("not an interrupt")

    Raises()
    assert [type(u.exc_value) for u in seen] == [ValueError]


def test_uninstall_puts_the_hook_back():
    before = sys.unraisablehook
    g = InterruptGuard()
    g.install()
    assert sys.unraisablehook != before
    g.uninstall()
    assert sys.unraisablehook == before
