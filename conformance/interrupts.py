"""Ctrl-C at any moment of a run: exit 2 with a report that says ``complete: false``, or, once
the run has finished, the finished report with its own exit code.

Python raises ``KeyboardInterrupt`` wherever the main thread happens to be. During pytest's
start-up that aborts the session before a report exists; inside a finalizer (``__del__``, a
weakref callback) it is swallowed as an "unraisable" warning and the run ends as if nothing
happened; after the verdicts are written it turns a finished run into exit 130. So a SIGINT
is first of all *recorded*, and raised only where pytest handles it (inside a case's setup,
call or teardown). A recorded interrupt is raised at the next case boundary if it was lost,
and at session end it makes the run incomplete. Once the run is *closed* (the moment its
completeness is decided) later interrupts change nothing.

The interrupt raised inside a case can still land in a finalizer or a gc callback that runs
in the middle of the case (hypothesis registers one); Python then prints it as "Exception
ignored" and drops it. The guard's unraisable hook drops only that interrupt, silently: it is
recorded, and the next case boundary or the session end acts on it.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any


class InterruptGuard:
    """The process's SIGINT policy while a conformance run is in progress."""

    def __init__(self) -> None:
        self.installed = False
        self.requested = False  # an interrupt arrived before the run was closed
        self.closed = False  # the run's completeness is decided: interrupts are too late
        self._armed = 0  # >0 inside a case: raise at once, pytest turns it into INTERRUPTED
        self._previous: Any = None
        self._previous_unraisable: Any = None

    def install(self) -> None:
        """Take over SIGINT (main thread only; elsewhere Python cannot deliver signals)."""
        if self.installed or threading.current_thread() is not threading.main_thread():
            return
        self._previous = signal.signal(signal.SIGINT, self._on_sigint)
        self._previous_unraisable = sys.unraisablehook
        sys.unraisablehook = self._on_unraisable
        self.installed = True

    def uninstall(self) -> None:
        if self.installed:
            signal.signal(signal.SIGINT, self._previous or signal.default_int_handler)
            self._restore_unraisable()
            self.installed = False

    def _restore_unraisable(self) -> None:
        if sys.unraisablehook == self._on_unraisable:
            sys.unraisablehook = self._previous_unraisable or sys.__unraisablehook__

    def _on_unraisable(self, unraisable: Any) -> None:
        """Drop the interrupt this guard raised where Python could not deliver it (it is
        recorded in ``requested``); hand everything else to the hook that was there."""
        if self.requested and isinstance(unraisable.exc_value, KeyboardInterrupt):
            return
        (self._previous_unraisable or sys.__unraisablehook__)(unraisable)

    def reset(self) -> None:
        """Forget an earlier run (a process that runs the suite twice, e.g. in tests)."""
        self.requested = self.closed = False
        self._armed = 0

    def _on_sigint(self, signum: int, frame: FrameType | None) -> None:
        if self.closed:
            print(
                "\ninterrupt ignored: the run had already finished; its report stands",
                file=sys.stderr,
            )
            return
        first = not self.requested
        self.requested = True
        if self._armed:
            raise KeyboardInterrupt
        if first:
            print("\ninterrupted: stopping at the next safe point", file=sys.stderr)

    @contextmanager
    def armed(self) -> Iterator[None]:
        """While a case runs, an interrupt stops it at once; a lost one stops it here."""
        if self.requested and not self.closed:
            raise KeyboardInterrupt
        self._armed += 1
        try:
            yield
        finally:
            self._armed -= 1

    def ignore_from_now(self) -> None:
        """After the summary: ignore SIGINT to the end of the process. (Python puts the
        default handler back while it shuts down, and a Ctrl-C there would kill the process
        with SIGINT, exit 130, after a finished run; an ignored signal stays ignored.)"""
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        self._restore_unraisable()
        self.installed = False

    def close(self) -> bool:
        """Decide: was the run interrupted? After this call interrupts are ignored."""
        self.closed = True
        return self.requested


GUARD = InterruptGuard()
