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
    col = 1 + names.index(channel)

    def parse(number: int, fields: list[str]) -> tuple[int, int]:
        try:
            ns = round(float(fields[0]) * NS)
            level = int(fields[col])
        except (ValueError, IndexError):
            raise CaptureError(path, f"line {number}: not a time and a 0/1 level") from None
        if level not in (0, 1):
            raise CaptureError(path, f"line {number}: level {fields[col]!r} is not 0 or 1")
        return ns, level

    try:
        number, fields = next(rows)
    except StopIteration:
        raise CaptureError(path, "no data rows: the export holds no samples") from None
    t0_ns, level = parse(number, fields)
    first_level = level
    # read ahead to estimate the sample period before handing out edges
    ahead: list[int] = []
    last = t0_ns
    for number, fields in rows:
        ns, new = parse(number, fields)
        if ns < last:
            raise CaptureError(path, f"line {number}: time goes backwards")
        last = ns
        if new != level:
            ahead.append(ns - t0_ns)
            level = new
            if len(ahead) >= PERIOD_SAMPLE_EDGES:
                break
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
    end = [last - t0_ns]

    def chunks() -> Iterator[list[int]]:
        nonlocal level
        if ahead:
            yield ahead
        chunk: list[int] = []
        prev = last
        for number, fields in rows:
            ns, new = parse(number, fields)
            if ns < prev:
                raise CaptureError(path, f"line {number}: time goes backwards")
            prev = ns
            if new != level:
                chunk.append(ns - t0_ns)
                level = new
                if len(chunk) >= CHUNK_ROWS:
                    yield chunk
                    chunk = []
        if chunk:
            yield chunk
        end[0] = prev - t0_ns

    return Edges(
        path=path,
        channel=channel,
        channels=names,
        tick_rate=NS,
        period=period,
        initial_level=first_level,
        chunks=chunks(),
        t0=t0_ns / NS,
        end=lambda: end[0],
        notes=notes,
    )
