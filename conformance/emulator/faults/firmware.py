"""Faults seen in real sensor firmware (issue 18) that no other family models: the ones the
multi-deviation profiles of :mod:`conformance.emulator.profiles` need beside existing faults.
"""

from __future__ import annotations

from .model import Fault

#: Found in public sensor firmware (issue 18).
FIRMWARE: tuple[Fault, ...] = (
    Fault(
        "unknown-command-text",
        "Commands the sensor does not know or serve are answered 'aUNKN<CR><LF>': text that"
        " is no command, unknown extended commands (both allowed, decision A12) and aRn!/aRCn!"
        " the sensor cannot serve (which must be answered 'a<CR><LF>' and 'a<CRC><CR><LF>').",
        ("R-4.4.8.1-03", "R-4.4.12-02"),
        settings={"unknown_reply": "UNKN"},
    ),
)
