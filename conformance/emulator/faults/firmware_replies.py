"""Faults modelled on what real firmware answers where the reference sensor is silent or
empty (issue 18): text of its own to every command it does not serve.
"""

from __future__ import annotations

from .model import Fault

#: Replies of real firmware to what it does not serve (issue 18).
FIRMWARE_REPLIES: tuple[Fault, ...] = (
    Fault(
        "never-standby",
        "The sensor never drops to standby, neither after 100 ms of marking nor after a"
        " command for another address: it answers after any marking, a 5 ms pulse included."
        " The spacing tests need a sensor shown in standby (R-7.0-03, R-7.0-04: precondition"
        " not met).",
        ("R-7.0-15", "R-7.0-14"),
        settings={"standby_marking": float("inf"), "standby_after_foreign": False},
        inconclusive=("R-7.0-03", "R-7.0-04"),
        masks=dict.fromkeys(
            ("standby-ignored", "stays-awake-after-foreign"),
            "never-standby is both of them at once: beside it neither is a deviation of its own",
        ),
    ),
    Fault(
        "unknown-command-text",
        "Every command the sensor does not serve (aR2..aR9!, aRC2..aRC9!, undefined aMn!/aCn!,"
        " an undeclared extended command, aDn! beyond the data) is answered 'aUNKN<CR><LF>'"
        " instead of the empty reply or silence.",
        # the R replies break the empty-reply rule; the undefined groups' text is no atttn(n)
        ("R-4.4.8.1-03", "R-4.4.5-01", "R-4.4.7-01"),
        settings={"unknown_reply": "UNKN"},
    ),
    Fault(
        "abort-sends-zero-reply",
        "After a break aborts its measurement, the sensor sends 'a0000<CR><LF>' unasked when"
        " the measurement would have been ready, unless the recorder talks before then (no"
        " service request: the abort itself holds).",
        ("R-4.4.5-08",),
        settings={"abort_reply": "0000"},
    ),
)
