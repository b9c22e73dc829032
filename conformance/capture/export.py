"""``export_events``: any transcript as a capture (.sr, .vcd, .csv), so a simulated run can be
opened in PulseView or Logic 2 next to a real one, or fed back to :func:`decode_capture`.

Default sample rate 100 kHz: 10 us per sample is 1/40 of the spec's 0.40 ms tolerance and
1/83 of a bit, so no verdict moves, while an hour of bus stays 360 M samples (a 1 MHz export
takes ten times the disk and the decoding time for no gain in what the judges can tell).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import repeat
from operator import attrgetter, eq

import numpy as np

from ..transcript import TOOL, Event, EventKind
from .comments import capture_comment
from .held_sr import hold_sr
from .levels import edge_array, wire_columns
from .writers import Channel, write_csv, write_sr, write_vcd

DEFAULT_SAMPLE_RATE = 100_000.0
LEAD = 0.020  # marking written before the first event, so a leading break is seen whole
TRAIL = 0.020  # marking after the last one
BUS_CHANNEL = "SDI12"
TOOL_CHANNEL = "TOOL_TX"
EXPORT_FORMATS = ("sr", "vcd", "csv")
_ORIGIN = attrgetter("origin")


@dataclass(frozen=True)
class ExportInfo:
    """What was written. ``t0``: the transcript time of the capture's first sample; a .sr or
    VCD cannot hold it, so decoding those gives times ``t0`` earlier than the transcript's
    (a CSV keeps the transcript's own times)."""

    path: str
    fmt: str
    sample_rate: float
    t0: float
    samples: int
    channels: tuple[str, ...]
    line_polarity: bool


def export_events(
    events: Sequence[Event],
    path: str,
    fmt: str | None = None,
    *,
    sample_rate: float = DEFAULT_SAMPLE_RATE,
    line_polarity: bool = False,
    tool_channel: bool = False,
    notes: Sequence[Event] = (),
    hold: bool = False,
) -> ExportInfo:
    """Write ``events`` as a capture at ``path``.

    ``fmt``: ``"sr"``, ``"vcd"`` or ``"csv"`` (default from the extension).
    ``line_polarity``: levels of the SDI-12 wire itself (marking low) instead of the UART side
    (marking high). ``tool_channel``: add a second channel holding only the tool's own
    transmissions (origin ``tool``), like a capture of the recorder's TX beside the bus.
    ``notes``: NOTE events kept in the file (a .sr member, a VCD ``$comment``, a CSV comment
    line), in capture time, with which channel is the bus and which the tool's; read back
    with :func:`~conformance.capture.comments.embedded_meta`. ``hold`` (a .sr only): the
    samples are not written but held as the edges they read back as, for a capture judged
    at once and deleted (:mod:`.held_sr`; inside :func:`~.held_sr.held_sr_captures`)."""
    path = str(path)
    fmt = (fmt or os.path.splitext(path)[1].lstrip(".")).lower()
    if fmt not in EXPORT_FORMATS:
        raise ValueError(f"export format {fmt!r}: expected one of {', '.join(EXPORT_FORMATS)}")
    if sample_rate <= 0:
        raise ValueError("sample rate must be positive")
    columns = wire_columns(events)
    wire = columns.events if columns is not None else _sorted_wire(events)
    if not wire:
        raise ValueError("no characters or breaks to export")
    first = wire[0].start
    t0 = 0.0 if LEAD <= first < 1.0 else first - LEAD  # keep a clock that starts near zero
    end = (float(columns.end.max()) if columns is not None else max(e.end for e in wire)) + TRAIL
    total = round((end - t0) * sample_rate)
    idle = 0 if line_polarity else 1
    if columns is not None:  # the columns read once for both channels
        edges = [columns.edges(sample_rate, t0)]
        if tool_channel:
            mine = np.fromiter(map(eq, map(_ORIGIN, wire), repeat(TOOL)), bool, len(wire))
            edges.append(columns.edges(sample_rate, t0, mine))
    else:
        edges = [edge_array(wire, sample_rate, t0)]
        if tool_channel:
            edges.append(edge_array([e for e in wire if e.origin == TOOL], sample_rate, t0))
    # an array for a .sr (written in bulk), Python ints for the text formats (written an
    # edge at a time)
    ticks = edges if fmt == "sr" else [e.tolist() for e in edges]
    channels = [Channel(BUS_CHANNEL, idle, ticks[0])]
    if tool_channel:
        channels.append(Channel(TOOL_CHANNEL, idle, ticks[1]))
    # a CSV keeps the transcript's clock, so its notes keep their own times
    comment = capture_comment(
        notes, 0.0 if fmt == "csv" else t0, BUS_CHANNEL, TOOL_CHANNEL if tool_channel else None
    )
    if hold and fmt != "sr":
        raise ValueError(f"only a .sr export is held without its samples, not a {fmt}")
    if fmt == "sr":
        write_sr(path, channels, sample_rate, total, comment=comment, samples=not hold)
        if hold:
            hold_sr(path, channels, sample_rate, total)
    else:
        with open(path, "w", encoding="ascii", newline="\n") as fh:
            if fmt == "vcd":
                write_vcd(fh, channels, sample_rate, total, comment=comment)
            else:
                write_csv(fh, channels, sample_rate, t0, comment=comment)
    return ExportInfo(
        path, fmt, sample_rate, t0, total, tuple(c.name for c in channels), line_polarity
    )


def _sorted_wire(events: Sequence[Event]) -> list[Event]:
    """The characters and breaks of ``events`` by start (stable), one at a time: the
    events :func:`~.levels.wire_columns` does not take."""
    return sorted(
        (e for e in events if e.kind in (EventKind.CHAR, EventKind.BREAK)), key=lambda e: e.start
    )
