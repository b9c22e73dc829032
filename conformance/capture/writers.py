"""Writers: transcript events as a capture PulseView or Logic 2 opens next to a real one.

Each writer takes per-channel edge streams (ticks at which the level toggles, from
:mod:`.levels`) and streams them out: a .sr is written a block of samples at a time (built
from the edges in bulk), VCD and CSV an edge at a time, so a one-hour run never becomes one
sample array.
"""

from __future__ import annotations

import heapq
import zipfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import TextIO

import numpy as np

BLOCK_SAMPLES = 1 << 22  # samples per logic-1-N member: 4 MiB at unitsize 1


@dataclass(frozen=True)
class Channel:
    """One channel to write: its name, level when idle (marking), and toggle ticks (an
    iterable, or an int64 array such as :func:`~.levels.edge_array` gives)."""

    name: str
    idle: int
    edges: Iterable[int] | np.ndarray


def _rate_text(rate: float) -> str:
    for unit, scale in (("GHz", 1e9), ("MHz", 1e6), ("kHz", 1e3)):
        if rate >= scale and rate % scale == 0:
            return f"{int(rate // scale)} {unit}"
    if rate != int(rate):
        raise ValueError(f"sample rate {rate} Hz is not a whole number of Hz")
    return f"{int(rate)} Hz"


def _words(channels: list[Channel], total: int) -> Iterator[np.ndarray]:
    """Blocks of sample words (channel N on bit N), ``BLOCK_SAMPLES`` at a time, built run by
    run with ``np.repeat`` from all channels' toggles at once. A channel's level at sample
    ``s`` is its idle level toggled once per edge at or before ``s`` (an edge earlier than
    one before it counts where that one was, edges from ``total`` on not at all): what
    filling a block edge by edge gave, without a Python step per edge."""
    if not channels:
        return
    ticks = []
    masks = []
    word = 0
    for bit, c in enumerate(channels):
        edges = np.asarray(
            c.edges if isinstance(c.edges, np.ndarray) else np.fromiter(c.edges, np.int64),
            dtype=np.int64,
        )
        if edges.size:
            edges = np.maximum.accumulate(edges)
            edges = edges[: np.searchsorted(edges, total, "left")]
        ticks.append(edges)
        masks.append(np.full(edges.size, 1 << bit, dtype=np.uint8))
        word |= (c.idle & 1) << bit
    at = np.concatenate(ticks) if ticks else np.zeros(0, dtype=np.int64)
    order = np.argsort(at, kind="stable")
    at = at[order]
    after = np.bitwise_xor.accumulate(np.concatenate(masks)[order]) ^ np.uint8(word)
    for base in range(0, total, BLOCK_SAMPLES):
        n = min(BLOCK_SAMPLES, total - base)
        lo, hi = np.searchsorted(at, (base, base + n), "left")
        values = np.empty(hi - lo + 1, dtype=np.uint8)
        values[0] = after[lo - 1] if lo else word
        values[1:] = after[lo:hi]
        bounds = np.empty(hi - lo + 2, dtype=np.int64)
        bounds[0] = 0
        bounds[1:-1] = at[lo:hi] - base
        bounds[-1] = n
        yield np.repeat(values, np.diff(bounds))


#: What leads a CSV comment line (PulseView's CSV import skips such lines by default).
CSV_COMMENT_LEADER = ";"

#: The .sr member holding an exporter's comment (sigrok ignores members it does not know).
SR_COMMENT_MEMBER = "sdi12-conform-comment"


def write_sr(
    path: str,
    channels: list[Channel],
    rate: float,
    total: int,
    level: int = 1,
    comment: str | None = None,
    samples: bool = True,
) -> None:
    """A sigrok session, version 2 (libsigrok >= 0.4): ``version``, ``metadata`` and the
    samples in ``logic-1-1``, ``logic-1-2``... one byte per sample, channel N on bit N-1.
    ``level``: deflate level (1 is several times faster than the default and the samples are
    runs, which compress well at any level). ``samples`` False: no sample member is written,
    the caller holds them (:func:`~.held_sr.hold_sr`)."""
    probes = "".join(f"probe{i + 1}={c.name}\n" for i, c in enumerate(channels))
    metadata = (
        "[global]\nsigrok version=0.5.2\n\n[device 1]\ncapturefile=logic-1\n"
        f"total probes={len(channels)}\nsamplerate={_rate_text(rate)}\ntotal analog=0\n"
        f"{probes}unitsize=1\n"
    )
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=level) as zf:
        zf.writestr("version", "2")
        zf.writestr("metadata", metadata)
        if comment:
            zf.writestr(SR_COMMENT_MEMBER, comment)
        for n, word in enumerate(_words(channels, total) if samples else (), 1):
            # the array's own buffer (zipfile takes any buffer: its CRC and deflate read
            # it in place), not a copy of 4 MiB a block
            zf.writestr(f"logic-1-{n}", memoryview(word))


def _merged(channels: list[Channel]) -> Iterator[tuple[int, int]]:
    """(tick, channel index) of every toggle of any channel, in time order."""

    def tagged(edges: Iterator[int], index: int) -> Iterator[tuple[int, int]]:
        for tick in edges:
            yield tick, index

    return heapq.merge(*(tagged(c.edges, i) for i, c in enumerate(channels)))


def _timescale(rate: float) -> str:
    period = 1.0 / rate
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9), ("ps", 1e-12)):
        for mult in (100, 10, 1):
            if abs(period - mult * scale) <= 1e-9 * period:
                return f"{mult} {unit}"
    raise ValueError(f"VCD needs a sample period of 1, 10 or 100 units; {rate} Hz has none")


def write_vcd(
    fh: TextIO, channels: list[Channel], rate: float, total: int, comment: str | None = None
) -> None:
    """A VCD with one 1-bit wire per channel, timescale = one sample period."""
    codes = [chr(33 + i) for i in range(len(channels))]
    fh.write(f"$date {datetime.now(UTC):%Y-%m-%d %H:%M:%S} UTC $end\n")
    fh.write("$version sdi12-conform capture export $end\n")
    if comment:
        if "$end" in comment or "\n" in comment:
            raise ValueError("a VCD comment is one line without '$end'")
        fh.write(f"$comment {comment} $end\n")
    fh.write(f"$timescale {_timescale(rate)} $end\n$scope module sdi12 $end\n")
    for c, code in zip(channels, codes, strict=True):
        fh.write(f"$var wire 1 {code} {c.name} $end\n")
    fh.write("$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n")
    levels = [c.idle for c in channels]
    for lvl, code in zip(levels, codes, strict=True):
        fh.write(f"{lvl}{code}\n")
    fh.write("$end\n")
    last = 0
    for tick, i in _merged(channels):
        levels[i] ^= 1
        if tick != last:
            fh.write(f"#{tick}\n")
            last = tick
        fh.write(f"{levels[i]}{codes[i]}\n")
    if total > last:
        fh.write(f"#{total}\n")


def write_csv(
    fh: TextIO, channels: list[Channel], rate: float, t0: float, comment: str | None = None
) -> None:
    """Saleae Logic 2 digital export: ``Time [s],<names>``, a row at the start and at every
    change, times in seconds with nanosecond digits (the transcript's own clock).
    ``comment``: one line written after the header behind :data:`CSV_COMMENT_LEADER` (the
    format has no other place for what the export knows about itself)."""
    levels = [c.idle for c in channels]
    fh.write("Time [s]," + ",".join(c.name for c in channels) + "\n")
    if comment:
        if "\n" in comment:
            raise ValueError("a CSV comment is one line")
        fh.write(f"{CSV_COMMENT_LEADER} {comment}\n")

    def row(tick: int) -> str:
        return f"{t0 + tick / rate:.9f}," + ",".join(map(str, levels)) + "\n"

    pending: int | None = 0
    for tick, i in _merged(channels):
        if pending is not None and tick != pending:
            fh.write(row(pending))
        levels[i] ^= 1
        pending = tick
    if pending is not None:
        fh.write(row(pending))
