"""The garbage collector's pace during a run.

A run allocates one object per bus event and several per judged observation, nearly none of
them in reference cycles, yet CPython's cyclic collector counts them all and, each time the
heap has grown by a quarter, walks every object there is: on the simulated bus that was a
fifth of a run's CPU (12 full collections over the 96,000 events of a faulty sensor's run).
So, for the run, what was loaded before it (pytest, the suite, the libraries) is moved out of
the collector's sight (:func:`gc.freeze`) and collections come every 20,000 net allocations
instead of every 700; both are undone when the run ends. Cyclic garbage is still collected,
only later.

A whole ``sdi12-conform`` process turns the collector off before its imports (the modules,
classes and functions it loads are never garbage, yet the collector walked them some dozens of
times before the first case) and after its run (the reports are written, the process ends
without freeing anything): :func:`slow_down` turns it on for the run whatever the caller did,
and :func:`restore` leaves it as it was found. A whole process whose run is in virtual time
(``--port sim``, an ``exec:`` harness) does not collect at all (:func:`never_in_this_process`).
"""

from __future__ import annotations

import gc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

#: generation thresholds during a run (CPython's default: 700, 10, 10)
RUN_THRESHOLDS = (20_000, 20, 20)


#: set by :func:`never_in_this_process`
_NEVER = False


def never_in_this_process() -> None:
    """No collections from here to the end of the process: for a process whose one job is a
    bounded run in virtual time. Such a run leaves next to no cyclic garbage (the peak memory
    of a whole ``--port sim`` process is the same with and without collections: 72 MB, 134 MB
    against wrong-crc), yet its collections walked its 10^5 events: 1.5% of the process's
    instructions. A real-time run, which lasts as long as the bus makes it, keeps collecting."""
    global _NEVER
    _NEVER = True
    gc.disable()


def freeze_for_libraries() -> None:
    """In a process that never collects (:func:`never_in_this_process`), move what exists out
    of the collector's sight before a library that calls ``gc.collect()`` itself is loaded
    (hypothesis's ``register_random``, once a process, walked every event of the run so far:
    about 10 ms). Nothing is lost: such a process collects nothing anyway, and the library's
    own objects, made after this, stay in sight. Elsewhere nothing changes."""
    if _NEVER and gc.get_freeze_count() and not gc.isenabled():
        gc.freeze()


@dataclass(frozen=True)
class Pace:
    """What :func:`slow_down` changed, for :func:`restore`."""

    thresholds: tuple[int, int, int]
    froze: bool
    #: whether the collector was on (a whole process turns it off outside its run)
    enabled: bool = True


def slow_down() -> Pace:
    """Collect less often until :func:`restore`, and collect at all (a run's cyclic garbage
    is collected whatever its caller did outside it); freeze what exists unless something
    else froze objects already (unfreezing would then thaw its objects too)."""
    pace = Pace(gc.get_threshold(), gc.get_freeze_count() == 0, gc.isenabled())
    if pace.froze:
        gc.freeze()
    if _NEVER:
        # nothing to pace (never_in_this_process), but what exists stays frozen: a library's
        # own gc.collect() (hypothesis's register_random makes one a process) then walks
        # only what the run made, not every module and object loaded before it
        return pace
    gc.set_threshold(*RUN_THRESHOLDS)
    gc.enable()
    return pace


def restore(pace: Pace) -> None:
    gc.set_threshold(*pace.thresholds)
    if pace.froze:
        gc.unfreeze()
    if not pace.enabled:
        gc.disable()


@contextmanager
def one_row() -> Iterator[None]:
    """The collector paused while a matrix's row is made, and the row's cyclic garbage
    collected when it ends (:func:`~conformance.matrices.sensor_matrix.paced_row`): a row,
    a run or two over the simulated bus, allocates some 10^5 objects that live until its end
    (the runs' events, records, observations) and leaves a few hundred in cycles. Paced by
    allocations (:data:`RUN_THRESHOLDS`), the collector walked the survivors of every 20,000
    of them, 7 young collections a row: ~4.5% of the sensor matrix's CPU (issue 22). Collected
    once a row instead, it walks only what outlived the row (the row's own objects are freed
    by their counts first: ``many_runs_plugin`` lets a FAIL's traceback go, which held its
    run in a cycle), and what outlived it is frozen with what the run's start froze. What a
    row holds at its peak grows by its cyclic garbage alone (a few dozen objects). A
    process whose collector is off (the CLI's own, :func:`never_in_this_process`) is left
    so."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.enable()
        gc.collect()
        if gc.get_freeze_count():
            # what outlived the row (the caches it filled) is not walked again at the next
            # row's end: frozen with what the run's start froze (:func:`slow_down`), and
            # thawed with it (4 ms a row); where nothing was frozen, nothing would thaw it
            gc.freeze()


@contextmanager
def runs_over_held_data() -> Iterator[Callable[[], None]]:
    """Several runs in turn over data loaded once (a passive judgement: a recording's events,
    view and records, then one run per sensor on the bus and one for the recorder). Yields
    ``collect``, to call between runs. Each run's pytest objects are cyclic garbage once it
    ends, and :func:`slow_down` froze them with the rest at the next run's start, so none was
    ever collected: about 0.85 MB a run held to the end (an 11-run judgement of a busy bus
    peaked 7-8 MB higher at 2 to 14 minutes; from 30 minutes on its peak comes in the first
    sensor's run, before that garbage exists, and is 1-2 MB lower only). So what exists now
    (the loaded data, never garbage) is frozen here, and ``collect`` walks only what the
    last run made (and freezes what outlived it): 79 ms for all 11 runs of an hour's
    capture, where one full collection walked its 10^6 events (0.08 s at 10 minutes).
    Nothing is frozen or collected if something else froze objects already (a thaw here
    would thaw its objects too) or if this process never collects
    (:func:`never_in_this_process`)."""
    froze = not _NEVER and gc.get_freeze_count() == 0
    if froze:
        gc.freeze()

    def collect() -> None:
        if froze:
            gc.collect()
            gc.freeze()  # what outlived the run (a memo it made) is not walked again

    try:
        yield collect
    finally:
        if froze:
            gc.unfreeze()
