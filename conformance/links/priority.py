"""Real-time scheduling for the threads that stamp or emit bytes.

On a busy machine an ordinary thread may get the CPU milliseconds after its byte arrived or
was due; the stamps (or the emulated sensor's frames) then carry that delay. Where the OS
allows it (Linux, as root or with an RTPRIO limit), the threads that read a port or keep an
emulated line in time ask for a real-time scheduling class, which other processes' ordinary
work cannot preempt. Where it is refused nothing changes, and the link's measurements show
what the delays cost.

Only threads that mostly sleep get the class. A real-time thread that computes (the tool's
judges) would trip the kernel's real-time throttling (95 % of a CPU per second), which then
stalls every real-time thread on that CPU, the emulated line included, for the rest of the
period: exactly the late frames this is meant to prevent.
"""

from __future__ import annotations

import os
import sys

# SCHED_RR priorities: all above every ordinary process, far below the kernel's own threads.
# A thread that stamps bytes outranks one that computes, and an emulated line (a stand-in for
# a sensor's own hardware) outranks the tool judging it on the same machine: a same-priority
# thread busy computing would otherwise hold the CPU for a whole round-robin slice (100 ms).
READER = 20
EMULATED_LINE = 30
# A sensor harness served on an emulated line (``emulate --harness``) is the sensor's own
# firmware: its answers are on the line's critical path (a reply goes out only once it has
# planned it), so it runs just below the line, above the tool's readers. It mostly sleeps
# on its input, as the threads given a class here must.
SERVED_FIRMWARE = EMULATED_LINE - 1
# The GIL hand-over interval while a real-time thread runs in the process (Python's default,
# 5 ms, lets a computing thread keep a reader or an emulated line waiting that long).
SWITCH_INTERVAL = 2e-4


def quick_gil_handover() -> float:
    """Lower the interpreter's switch interval to :data:`SWITCH_INTERVAL` (never raise it) for
    as long as a real-time thread runs here; returns the interval to put back afterwards."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(min(previous, SWITCH_INTERVAL))
    return previous


def realtime_priority(priority: int = READER, pid: int = 0) -> bool:
    """Give the calling thread (or the process ``pid``) SCHED_RR; False where the OS refuses
    (or has no such thing)."""
    setter = getattr(os, "sched_setscheduler", None)
    policy = getattr(os, "SCHED_RR", None)
    if setter is None or policy is None:
        return False
    policy |= getattr(os, "SCHED_RESET_ON_FORK", 0)  # a child process starts ordinary
    try:
        setter(pid, policy, os.sched_param(priority))
    except (OSError, AttributeError):
        return False
    return True
