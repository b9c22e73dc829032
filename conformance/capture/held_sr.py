"""A sigrok session's samples held as the edges they read back as, for a capture judged
straight away and deleted (a fault-matrix row's round trip, issue 22).

A matrix row's export is 3*10^7 samples at 100 kHz: rendering them (``np.repeat``, deflate,
CRC) and reading them back (inflate, a pass for transitions) was ~0.09 s of a ~1.1 s row,
for edges the export already had. :func:`hold_sr` keeps, per channel, the starting level and
the ticks :func:`~.sigrok.read_sr` would find in the written samples, chunked as its
block-by-block pass gives them;
the file on disk holds the session's metadata and comment, no sample member.
:func:`~.sigrok.read_sr` of that file, while :func:`held_sr_captures` lasts, gives those
edges to the same decoder a user's ``judge`` runs. ``tests/capture/test_held_sr.py`` checks
them against the written file's, read back, chunk for chunk. A user's ``export`` writes its
samples, as before.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from . import writers
from .edges import Edges
from .errors import CaptureError
from .writers import Channel


@dataclass(frozen=True)
class HeldSr:
    """A session as :func:`~.sigrok.read_sr` would read it: sample rate, the capture's
    length in samples, and per channel (in probe order) its first level and edge chunks."""

    samplerate: float
    total: int
    channels: dict[str, tuple[int, np.ndarray]]


#: held sessions by file identity (real path, mtime, size): a file written again is not held
_HELD: dict[tuple, HeldSr] = {}


def read_back(channel: Channel, total: int) -> tuple[int, np.ndarray]:
    """``channel``'s first level and edge ticks as :func:`~.writers.write_sr` writes its
    samples and :func:`~.sigrok.read_sr` finds them again: edges made non-decreasing and cut
    at ``total`` (as :func:`~.writers._words`), toggles at one tick cancelling in pairs (the
    sample level changes only on an odd count), those at or before tick 0 setting the first
    level."""
    edges = np.asarray(
        channel.edges
        if isinstance(channel.edges, np.ndarray)
        else np.fromiter(channel.edges, np.int64),
        dtype=np.int64,
    )
    if edges.size:
        edges = np.maximum.accumulate(edges)
        edges = edges[: np.searchsorted(edges, total, "left")]
    ticks = edges
    if edges.size > 1 and not (np.diff(edges) > 0).all():  # an export's are strictly rising
        first = np.flatnonzero(np.append(True, edges[1:] != edges[:-1]))  # of each run
        counts = np.diff(np.append(first, edges.size))
        ticks = edges[first[(counts & 1) == 1]]
    lead = int(np.searchsorted(ticks, 0, "right"))  # toggles of sample 0 itself
    return (channel.idle & 1) ^ (lead & 1), ticks[lead:]


def block_starts(total: int, block: int) -> list[int]:
    """The first sample of each block :func:`~.sigrok.read_sr`'s pass takes of a session
    :func:`~.writers.write_sr` wrote: every member (:data:`~.writers.BLOCK_SAMPLES`
    samples) read ``block`` samples at a time."""
    member = writers.BLOCK_SAMPLES
    return [m + k for m in range(0, total, member) for k in range(0, min(member, total - m), block)]


def _identity(path: str) -> tuple:
    st = os.stat(path)
    return (os.path.realpath(path), st.st_mtime_ns, st.st_size)


def hold_sr(path: str, channels: list[Channel], rate: float, total: int) -> None:
    """Hold the samples of the session just written at ``path`` without them (see the
    module) until :func:`held_sr_captures` ends."""
    _HELD[_identity(path)] = HeldSr(rate, total, {c.name: read_back(c, total) for c in channels})


def held_edges(path: str, channel: str | None, block: int) -> Edges | None:
    """:func:`~.sigrok.read_sr` of a held session (None: ``path`` is not one), whose pass
    takes ``block`` samples at a time: ``channel``, or the one that changes most in the
    first block, as the reader chooses; a chunk of edges per block that has any."""
    try:
        held = _HELD.get(_identity(path))
    except OSError:
        return None
    if held is None:
        return None
    names = list(held.channels)
    notes: list[str] = []
    if channel is None:
        channel = names[0]
        if len(names) > 1:
            end = min(block, writers.BLOCK_SAMPLES, held.total)
            first = {n: int(np.searchsorted(held.channels[n][1], end, "left")) for n in names}
            channel = max(first, key=lambda n: first[n])
            notes.append(f"channel {channel!r} chosen: it changes level most at the start")
    if channel not in held.channels:
        raise CaptureError(path, f"no channel {channel!r}; channels present: {', '.join(names)}")
    level, ticks = held.channels[channel]
    total = held.total
    cuts = np.searchsorted(ticks, block_starts(total, block)[1:], "left")
    chunks = [c for c in np.split(ticks, cuts) if c.size]
    return Edges(
        path=path,
        channel=channel,
        channels=names,
        tick_rate=held.samplerate,
        period=1.0 / held.samplerate,
        initial_level=level,
        chunks=(c.tolist() for c in chunks),
        end=lambda: total or None,
        notes=notes,
        min_gap=int(np.diff(ticks).min()) if ticks.size > 1 else None,
    )


@contextmanager
def held_sr_captures() -> Iterator[None]:
    """What :func:`hold_sr` holds while this lasts is let go at its end."""
    try:
        yield
    finally:
        _HELD.clear()
