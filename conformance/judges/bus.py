"""The bus cases' rules (issue 23, item 2): what one sensor of a shared line does while the
others are addressed and answer. Pure functions over records and transcript events.

On a real bus every sensor's characters arrive as the DUT's (origin ``dut``): which sensor
spoke is read from the line's first character, its address, as every SDI-12 recorder reads it.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..tool_recorder.records import Exchange, Measurement
from ..transcript import TOOL, Event, EventKind, escape
from ..verdicts import Finding, failed, inconclusive, passed
from .cite import cite, heard


def sensor_lines(events: Sequence[Event]) -> list[list[Event]]:
    """The sensors' characters among ``events`` cut into lines (each through its LF; a line
    left open at the end is kept), the tool's characters and breaks ending a line too."""
    lines: list[list[Event]] = []
    current: list[Event] = []
    for event in events:
        if event.kind is EventKind.NOTE:
            continue
        if event.origin == TOOL or event.kind is not EventKind.CHAR:
            if current:
                lines.append(current)
            current = []
            continue
        current.append(event)
        if event.char7 == 0x0A:
            lines.append(current)
            current = []
    if current:
        lines.append(current)
    return lines


def _lines_by_start(events: Sequence[Event]) -> tuple[list[list[Event]], list[list[Event]]]:
    """The sensor lines that surely start a transmission (the first, or one after a line
    that reached its LF), and the rest: the remainder of a line the tool's own
    transmission cut, whose first character may be the middle of another sensor's reply."""
    whole: list[list[Event]] = []
    cut: list[list[Event]] = []
    ended = True
    for line in sensor_lines(events):
        (whole if ended else cut).append(line)
        ended = line[-1].char7 == 0x0A
    return whole, cut


def kept_through_bus(
    dut: Measurement, undisturbed: int, others_heard: Sequence[Exchange]
) -> list[Finding]:
    """R-4.4.7-05: the DUT's concurrent measurement, started before the other sensors were
    addressed and answered (``others_heard``), delivered as many values as undisturbed."""
    code = dut.command.text()
    others = ", ".join(sorted({ex.command.address for ex in others_heard if ex.command}))
    said = (
        f"{code} delivered {dut.value_count} values after {len(others_heard)} replies of the "
        f"sensor(s) at {others} to commands sent while it ran"
    )
    if dut.value_count >= undisturbed:
        return [passed("R-4.4.7-05", f"{said}, as many as undisturbed", observed=dut.value_count)]
    return [
        failed(
            "R-4.4.7-05",
            f"{said}, {undisturbed} undisturbed: the traffic to other sensors aborted it",
            evidence=cite([dut.start, *others_heard[:3], *dut.data]),
            observed=2,  # the undisturbed measurement and this one
        )
    ]


def silent_among_others(
    address: str, window: Sequence[Event], others_heard: Sequence[Exchange]
) -> list[Finding]:
    """R-4.0-01: while its concurrent measurement waited, the DUT said nothing: no line of
    the ``window`` (from its ``atttnn`` to its ``aD0!``) starts with its address, though the
    other sensors were addressed and answered (``others_heard``) and their data were read."""
    whole, cut = _lines_by_start(window)
    own = [line for line in whole if chr(line[0].char7) == address]
    unsure = [line for line in cut if chr(line[0].char7) == address]
    if not own and unsure:
        shown = "; ".join(heard(line, "cut line") for line in unsure[:3])
        return [
            inconclusive(
                "R-4.0-01",
                f"{len(unsure)} line(s) starting with its address '{escape(address)}' were cut "
                f"by the tool's own transmissions ({shown}): whose they were cannot be told",
            )
        ]
    if not own:
        shaped = sum(
            1 for ex in others_heard if ex.command and ex.reply_text == f"{ex.command.address}\r\n"
        )
        return [
            passed(
                "R-4.0-01",
                f"silent through {len(others_heard)} commands to other sensors and their "
                f"replies ({shaped} of them 'b<CR><LF>', a service request's shape), while "
                "its own concurrent measurement waited",
                observed=len(others_heard),
            )
        ]
    shown = "; ".join(heard(line, "the DUT sent") for line in own[:3])
    first = own[0][0].start
    before = [ex for ex in others_heard if ex.reply_events and ex.reply_events[-1].end <= first]
    return [
        failed(
            "R-4.0-01",
            f"{len(own)} line(s) starting with its address '{escape(address)}' came while only "
            "other sensors were addressed: it answered traffic that was not for it",
            evidence=[shown, *cite(before[-1:])],
            observed=len(others_heard),
        )
    ]


__all__ = ["kept_through_bus", "sensor_lines", "silent_among_others"]
