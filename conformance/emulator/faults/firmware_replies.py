"""Faults modelled on what real firmware answers where the reference sensor is silent or
empty (issue 18): text of its own to every command it does not serve.
"""

from __future__ import annotations

from .model import Fault

#: Replies of real firmware to what it does not serve (issue 18).
FIRMWARE_REPLIES: tuple[Fault, ...] = (
    Fault(
        "unknown-command-text",
        "Every command the sensor does not serve (aR2..aR9!, aRC2..aRC9!, undefined aMn!/aCn!,"
        " an undeclared extended command, aDn! beyond the data) is answered 'aUNKN<CR><LF>'"
        " instead of the empty reply or silence.",
        # the R replies break the empty-reply rule; the undefined groups' text is no atttn(n)
        ("R-4.4.8.1-03", "R-4.4.5-01", "R-4.4.7-01"),
        settings={"unknown_reply": "UNKN"},
    ),
)
