"""Faults only a bus of several sensors shows (issue 23, item 2): what a sensor does with
another sensor's reply while its own concurrent measurement runs.

A sensor alone on the line never hears a reply but its own, so these faults are invisible to
the single-sensor suite and its matrix (``Fault.bus``); the bus cases
(``testcases/sensor/test_bus.py``) on ``sim://?sensors=0,1:FAULT,3`` catch them.
"""

from __future__ import annotations

from .model import Fault

#: Deviations on a shared bus.
BUS: tuple[Fault, ...] = (
    Fault(
        "aborts-on-foreign-reply",
        "A running C/CC measurement is dropped when another sensor's reply is heard on the "
        "bus (D then returns nothing); only a bus shows it: sim://?sensors=0,1:NAME,3.",
        ("R-4.4.7-05",),
        settings={"foreign_reply_aborts_concurrent": True},
        bus=True,
    ),
    Fault(
        "answers-foreign-reply",
        "While a C/CC measurement runs, another sensor's reply heard on the bus is taken for "
        "a command to this sensor and answered with its address; only a bus shows it.",
        ("R-4.0-01",),
        settings={"answer_foreign_reply": True},
        bus=True,
    ),
)
