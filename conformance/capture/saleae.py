"""Saleae Logic 2 digital CSV exports: ``Time [s],Channel 0,Channel 1,...`` then one row per
change of any channel (Logic 1.x wrote ``Time[s], Channel 0``: also accepted).

The export carries times, not samples, and not the sample rate. Times are turned into integer
nanoseconds (exact for any rate Logic supports) and the sample period is estimated as the
greatest common divisor of the first edges' spacings, which is the sample period whenever the
analyzer's clock is a whole number of nanoseconds (every Saleae rate up to 500 MHz is).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from .edges import Edges
from .errors import CaptureError
from .writers import CSV_COMMENT_LEADER

NS = 1_000_000_000
CHUNK_ROWS = 4096
PERIOD_SAMPLE_EDGES = 2000  # edges used to estimate the sample period


def _rows(path: str) -> Iterator[tuple[int, list[str]]]:
    """(line number, fields) of each non-empty line that is not a comment (an export's own
    metadata line, :mod:`.comments`), without loading the file."""
    try:
        with open(path, encoding="utf-8", errors="strict", newline="") as fh:
            for number, line in enumerate(fh, 1):
                line = line.strip()
                if line and not line.startswith(CSV_COMMENT_LEADER):
                    yield number, [f.strip().strip('"') for f in line.split(",")]
    except UnicodeDecodeError:
        raise CaptureError(path, "not text: binary data in a CSV export") from None


def read_csv(path: str, channel: str | None = None) -> Edges:
    rows = _rows(path)
    names, channel, notes = _header(path, rows, channel)
    col = 1 + names.index(channel)
    try:
        number, fields = next(rows)
    except StopIteration:
        raise CaptureError(path, "no data rows: the export holds no samples") from None
    t0_ns, first_level = _parse_row(path, col, number, fields)
    end = [0]
    # read ahead to estimate the sample period before handing out edges
    stream = _edge_chunks(path, rows, col, t0_ns, first_level, end)
    ahead = next(stream)
    period = _period(ahead, notes)
    return Edges(
        path=path,
        channel=channel,
        channels=names,
        tick_rate=NS,
        period=period,
        initial_level=first_level,
        chunks=_handed_out(ahead, stream),
        t0=t0_ns / NS,
        end=lambda: end[0],
        notes=notes,
    )


def _header(
    path: str, rows: Iterator[tuple[int, list[str]]], channel: str | None
) -> tuple[list[str], str, list[str]]:
    """The channel names, the channel chosen (the first unless named) and the notes so far,
    from the header row: an export that is not Saleae's is refused before any data is read."""
    try:
        _, header = next(rows)
    except StopIteration:
        raise CaptureError(path, "empty file") from None
    if not header or not header[0].lower().replace(" ", "").startswith("time"):
        raise CaptureError(path, "not a Saleae export: the first column is not 'Time [s]'")
    names = header[1:]
    if not names:
        raise CaptureError(path, "no channel columns after 'Time [s]'")
    notes: list[str] = []
    if channel is None:
        channel = names[0]
        if len(names) > 1:
            notes.append(f"channel {channel!r} chosen: the first column (use a channel name)")
    if channel not in names:
        raise CaptureError(path, f"no channel {channel!r}; channels present: {', '.join(names)}")
    return names, channel, notes


def _parse_row(path: str, col: int, number: int, fields: list[str]) -> tuple[int, int]:
    """(ns, level) of one data row: the first row and every later one are read alike."""
    try:
        ns = round(float(fields[0]) * NS)
        level = int(fields[col])
    except (ValueError, IndexError):
        raise CaptureError(path, f"line {number}: not a time and a 0/1 level") from None
    if level not in (0, 1):
        raise CaptureError(path, f"line {number}: level {fields[col]!r} is not 0 or 1")
    return ns, level


def _edge_chunks(
    path: str,
    rows: Iterator[tuple[int, list[str]]],
    col: int,
    t0_ns: int,
    level: int,
    end: list[int],
) -> Iterator[list[int]]:
    """The edges of column ``col`` (ns after ``t0_ns``, the first row's time, at ``level``)
    in chunks: one loop over the rows both for the read-ahead and for the edges handed out
    after it. The first chunk (up to :data:`PERIOD_SAMPLE_EDGES` edges, possibly empty) is
    always yielded, with ``end[0]`` set to the last row read; then chunks of
    :data:`CHUNK_ROWS`, and ``end[0]`` is the last row's time once the rows are exhausted."""
    chunk: list[int] = []
    size = PERIOD_SAMPLE_EDGES
    ahead = True  # the first chunk (the read-ahead) is not yet out
    prev = t0_ns
    for number, fields in rows:
        ns, new = _parse_row(path, col, number, fields)
        if ns < prev:
            raise CaptureError(path, f"line {number}: time goes backwards")
        prev = ns
        if new != level:
            chunk.append(ns - t0_ns)
            level = new
            if len(chunk) >= size:
                if ahead:
                    end[0] = prev - t0_ns
                    ahead = False
                    size = CHUNK_ROWS
                yield chunk
                chunk = []
    if ahead:
        end[0] = prev - t0_ns
        yield chunk
    elif chunk:
        yield chunk
    end[0] = prev - t0_ns


def _period(ahead: list[int], notes: list[str]) -> float:
    """The sample period (s) as the gcd of the read-ahead edges' spacings (a CSV states no
    rate), noting the estimate; one nanosecond when there are no edges to tell."""
    gcd = 0
    previous = 0
    for tick in ahead:
        gcd = math.gcd(gcd, tick - previous)
        previous = tick
    period = gcd / NS if gcd else 1 / NS
    if gcd:
        notes.append(
            f"sample period {period * 1e9:g} ns estimated from the edges (CSV has no rate)"
        )
    return period


def _handed_out(ahead: list[int], rest: Iterator[list[int]]) -> Iterator[list[int]]:
    """The read-ahead chunk (unless empty), then the rest: the edges a consumer is given."""
    if ahead:
        yield ahead
    yield from rest
