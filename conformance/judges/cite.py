"""Evidence lines naming exchanges and heard characters (issue 18: a FAIL or WARN names the
observations it rests on). Apart from the judges so that the precondition checks, which the
judges and the case object use, cite the wire the same way without importing either."""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

from ..tool_recorder.records import Exchange
from ..transcript import Event, decode_7e1, escape

#: an evidence line's time on the link clock, as :func:`cited` and the judges write it
#: ("t=1.2345 s"); read back by the reports and by the served line's guard
STAMP = re.compile(r"\bt=(\d+(?:\.\d+)?) ?s\b")


def shown(ex: Exchange) -> str:
    """``0I! -> '0I13VENDOR..<CR><LF>'`` for evidence lines."""
    reply = escape(ex.reply_text) if ex.answered else "(silence)"
    note = " (maybe collided: sensor characters met the command)" if ex.maybe_collided else ""
    return f"{escape(ex.text)} -> '{reply}'{note}"


def cited(ex: Exchange) -> str:
    """``t=1.2345 s: 0I! -> '0I13VENDOR..<CR><LF>'``: an evidence line naming the exchange a
    FAIL or WARN rests on, with the time its command began (issue 18)."""
    return f"t={ex.start:.4f} s: {shown(ex)}"


def cite(exchanges: Iterable[Exchange]) -> list[str]:
    """Evidence lines for ``exchanges`` (:func:`cited`)."""
    return [cited(ex) for ex in exchanges]


def heard(events: list[Event], what: str) -> str:
    """``t=1.2345 s: service request '0<CR><LF>'``: an evidence line for characters heard
    outside any exchange (a service request, stray bytes), with when they began."""
    start = f"t={events[0].start:.4f} s: " if events else ""
    return f"{start}{what} '{escape(decode_7e1(events))}'"


def listed(lines: Sequence[str], limit: int = 3) -> str:
    """``a; b; c (+2 more)``: the first ``limit`` lines of a finding's detail, and how many
    it leaves out (the evidence keeps them all)."""
    more = len(lines) - limit
    return "; ".join(lines[:limit]) + (f" (+{more} more)" if more > 0 else "")
