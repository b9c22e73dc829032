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
