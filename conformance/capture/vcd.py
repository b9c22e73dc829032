"""Value change dumps (VCD, IEEE 1364): the subset logic analyzers write.

A small streaming parser of our own rather than a PyPI reader: the subset needed is tiny
(``$timescale``, ``$var wire 1``, ``#time``, ``0x``/``1x`` scalar and ``b0 x`` vector changes)
and reading line by line keeps memory flat for any file length. Ticks are timescale units; the
timescale is taken as the sample period (PulseView and Logic write one unit per sample).
"""

from __future__ import annotations

import re
from collections.abc import Iterator

from .edges import Edges
from .errors import CaptureError

CHUNK = 4096
_SCALE = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "ps": 1e-12, "fs": 1e-15}


def _tokens(path: str) -> Iterator[str]:
    try:
        with open(path, encoding="ascii", errors="strict") as fh:
            for line in fh:
                yield from line.split()
    except UnicodeDecodeError:
        raise CaptureError(path, "not text: binary data in a VCD file") from None


def read_vcd(path: str, channel: str | None = None) -> Edges:
    tokens = _tokens(path)
    scale, wires = _header(path, tokens)
    notes: list[str] = []
    if channel is None:
        channel = next(iter(wires))
        if len(wires) > 1:
            notes.append(f"channel {channel!r} chosen: the first signal (use a channel name)")
    if channel not in wires:
        raise CaptureError(path, f"no channel {channel!r}; channels present: {', '.join(wires)}")
    end = [0]
    stream = _changes(path, tokens, wires[channel], end)
    # the value at the first timestamp is the starting level: read up to the first change
    first = next(stream, None)
    if first is None:
        raise CaptureError(path, f"signal {channel!r} never has a 0/1 value")
    start, first_level = first
    return Edges(
        path=path,
        channel=channel,
        channels=list(wires),
        tick_rate=1.0 / scale,
        period=scale,
        initial_level=first_level,
        chunks=_chunks(stream, start, first_level),
        t0=start * scale,
        end=lambda: end[0] - start,
        notes=notes,
    )


def _until_end(tokens: Iterator[str]) -> list[str]:
    """The tokens of a header section up to its ``$end`` (consumed, not returned)."""
    text = []
    for t in tokens:
        if t == "$end":
            break
        text.append(t)
    return text


def _header(path: str, tokens: Iterator[str]) -> tuple[float, dict[str, str]]:
    """The timescale (s per tick; 1 ns when the header has none) and the 1-bit wires (name
    -> identifier code) of the header, read up to ``$enddefinitions`` so that ``tokens`` is
    left at the first value change."""
    scale: float | None = None
    wires: dict[str, str] = {}  # name -> identifier code
    for tok in tokens:
        if tok == "$timescale":
            text = _until_end(tokens)
            m = re.fullmatch(r"(1|10|100)\s*(s|ms|us|ns|ps|fs)", "".join(text))
            if not m:
                raise CaptureError(path, f"bad $timescale {' '.join(text)!r}")
            scale = int(m.group(1)) * _SCALE[m.group(2)]
        elif tok == "$var":
            fields = _until_end(tokens)
            if len(fields) >= 4 and fields[1] == "1":
                wires.setdefault(fields[3], fields[2])
        elif tok == "$enddefinitions":
            _until_end(tokens)
            break
        elif tok in ("$date", "$version", "$comment", "$scope", "$upscope"):
            _until_end(tokens)
    else:
        raise CaptureError(path, "no '$enddefinitions': not a complete VCD header")
    if not wires:
        raise CaptureError(path, "no 1-bit '$var wire' signals in the VCD header")
    return (1e-9 if scale is None else scale), wires


def _value_of(tok: str, tokens: Iterator[str]) -> tuple[str, str] | None:
    """(identifier, value) for a change token, or None if it is not one."""
    if tok[0] in "01xXzZ":
        return tok[1:], tok[0]
    if tok[0] in "bB":
        ident = next(tokens, "")
        return ident, tok[-1]
    if tok[0] in "rR":
        next(tokens, "")
    return None


def _changes(
    path: str, tokens: Iterator[str], code: str, end: list[int]
) -> Iterator[tuple[int, int]]:
    """(time, 0/1 value) of every change of the wire ``code``, repeated values included;
    ``end[0]`` follows the latest timestamp, the capture's end once the tokens run out."""
    time = 0
    for tok in tokens:
        if tok[0] == "#":
            try:
                new = int(tok[1:])
            except ValueError:
                raise CaptureError(path, f"bad timestamp {tok!r}") from None
            if new < time:
                raise CaptureError(path, f"time goes backwards at {tok}")
            time = new
            end[0] = time
            continue
        if tok[0] == "$":
            continue  # $dumpvars / $end / $dumpall around ordinary changes
        change = _value_of(tok, tokens)
        if change is not None and change[0] == code and change[1] in "01":
            yield time, int(change[1])


def _chunks(stream: Iterator[tuple[int, int]], start: int, level: int) -> Iterator[list[int]]:
    """The ticks (after ``start``) where the value really toggles from ``level``, in chunks
    of :data:`CHUNK`: a VCD may repeat a value, which is no edge."""
    chunk: list[int] = []
    for t, value in stream:
        if value != level:
            level = value
            chunk.append(t - start)
            if len(chunk) >= CHUNK:
                yield chunk
                chunk = []
    if chunk:
        yield chunk
