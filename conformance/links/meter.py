"""What a real link's stamps are worth, measured on the run itself (design.md section 4).

A link declares a floor for its timing uncertainty (what it cannot see: the latency of a USB
chip, of the far end of a network). Everything the run can observe about its own stamps goes
into a :class:`TimingMeter`, and the uncertainty the judges use is the larger of the floor
and the worst observation:

- **echo spread**: the tool's own characters leave the UART back to back; where the
  interface echoes them, the spread of their arrival times about that known spacing is the
  receive path's jitter, measured;
- **batches**: bytes that reach the host together hide the gaps between them; a batch of k
  bytes proves the path's latency varied by at least (k-1) character times;
- **artefacts**: stamps that are physically impossible (a frame starting before the previous
  one ended) are link artefacts: their size is a lower bound of the stamps' error;
- **reader lag**: how late the reader thread woke (kernel stamp against the thread's own, or
  a timed read's overrun). It only widens the uncertainty where the link's stamps come from
  the thread (no kernel stamps).

With echo, the DUT's timing is measured against the echoed command on the same receive path
(the ``echo`` reference), so the path's fixed latency cancels and only its jitter remains;
without it, against the moment the tool wrote (the ``write`` reference), where the latency
stays in the declared floor.

Irregularities are also **local**: a machine that stalls for a few milliseconds once in a
thousand characters makes the stamps around that moment wrong, not every stamp of the run.
Each artefact, batch and echo spread far beyond the usual one is kept as a *taint* (a time
span and the error it shows there); :meth:`TimingMeter.between` gives the uncertainty of a
measurement between two instants: the run's regular figure, or the taint it touches. The
regular figure is the worst echo spread once such outliers are set aside (they are taints).
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from itertools import takewhile

ECHO_FLOOR = 0.25e-3  # s: least uncertainty claimed on one receive path (UART sampling, clocks)
OUTLIER_FACTOR = 2.0  # an echo spread beyond this many times the 90th percentile...
OUTLIER_MARGIN = 0.5e-3  # ...plus this is a local stall (a taint), not the path's jitter
MIN_SPREADS = 10  # fewer round trips than this: no typical one yet
# Fewer echo spreads than this: the worst one is the regular figure. Setting the top tenth
# aside as stalls needs enough spreads for a tenth to be rare: a 16 ms latency timer makes
# a command's echo spread 0 or 7.7 ms by the phase of its tick, and in a 16-spread probe one
# or two 7.7 ms spreads are that bench's jitter, not a stall.
MIN_FOR_OUTLIERS = 30


@dataclass(frozen=True)
class Taint:
    """Stamps between ``start`` and ``end`` (s, link clock) may be off by ``error`` (s)."""

    start: float
    end: float
    error: float
    why: str


@dataclass
class Worst:
    """The largest of a kind of sample, where it was seen, and how many were taken."""

    value: float = 0.0
    count: int = 0
    where: str = ""

    def add(self, value: float, where: str = "") -> None:
        self.count += 1
        if value > self.value:
            self.value, self.where = value, where


@dataclass
class TimingMeter:
    """What a run's stamps are worth, measured as it goes: the declared floor, and the worst
    echo spread, batching, artefacts and reader lag seen (the run's timing uncertainty)."""

    declared: float  # s: the link's declared floor without echo (latency it cannot see)
    kernel_stamps: bool = False
    echo_spread: Worst = field(default_factory=Worst)
    batches: Worst = field(default_factory=Worst)
    artefacts: Worst = field(default_factory=Worst)
    reader_lag: Worst = field(default_factory=Worst)
    round_trip: Worst = field(default_factory=Worst)  # write call to echo: fixed latency
    turnaround: Worst = field(default_factory=Worst)  # last stop bit to driver released
    widen_to: float = 0.0  # s: the user's --timing-uncertainty-ms (may only widen)
    echo: bool = False  # the run measures against the echo of its own characters
    taints: list[Taint] = field(default_factory=list)
    spreads: list[tuple[float, float, float]] = field(default_factory=list)  # start, end, s

    trips: list[float] = field(default_factory=list)  # write-to-echo delays so far
    # what between() asks of the taints and spreads, rebuilt when either list has grown (both
    # are only appended to): a whole-run judge asks once a gap, 3*10^4 times on a full run,
    # and scanning 10^3 taints and sorting the spreads each time cost 0.7 s of the run's wall
    _taint_index: _TaintIndex | None = field(default=None, repr=False, compare=False)
    _spread_cache: tuple[int, float, list[tuple[float, float, float]]] | None = field(
        default=None, repr=False, compare=False
    )

    def typical_round_trip(self) -> float | None:
        """The median write-to-echo delay so far (None before a few were seen)."""
        if len(self.trips) < MIN_SPREADS:
            return None
        ordered = sorted(self.trips)
        return ordered[len(ordered) // 2]

    def taint(self, start: float, end: float, error: float, why: str) -> None:
        self.taints.append(Taint(start, end, error, why))

    def spread(self, start: float, end: float, value: float, where: str) -> None:
        """An echoed transmission between ``start`` and ``end`` spread by ``value`` (s)."""
        self.echo_spread.add(value, where)
        self.spreads.append((start, end, value))

    def regular_spread(self) -> float:
        """The echo spread the receive path shows when nothing unusual happens: the worst
        one once outliers (local stalls, kept as taints) are set aside."""
        return self._spread_figures()[1]

    def _spread_figures(self) -> tuple[int, float, list[tuple[float, float, float]]]:
        """(spreads counted, :meth:`regular_spread`, the outlier spreads), from the spreads
        as they are now; recomputed only when more have come."""
        cached = self._spread_cache
        count = len(self.spreads)
        if cached is not None and cached[0] == count:
            return cached
        spreads = self.spreads[:count]
        values = sorted(v for _s, _e, v in spreads)
        outliers: list[tuple[float, float, float]] = []
        if not values:
            regular = 0.0
        elif len(values) < MIN_FOR_OUTLIERS:
            regular = values[-1]
        else:
            cut = self._outlier_cut(values)
            regular = max(v for v in values if v <= cut)
            outliers = [sp for sp in spreads if sp[2] > cut]
        self._spread_cache = (count, regular, outliers)
        return self._spread_cache

    def _outlier_cut(self, values: list[float]) -> float:
        p90 = values[int(0.9 * (len(values) - 1))]
        return OUTLIER_FACTOR * p90 + OUTLIER_MARGIN

    def between(self, start: float, end: float) -> float:
        """Uncertainty (s) of a measurement between two instants: the regular figure, or
        more where the run showed its stamps irregular near them."""
        index = self._taint_index
        if index is None or index.count != len(self.taints):
            index = self._taint_index = _TaintIndex(self.taints)
        u = index.worst(start, end, self.uncertainty())
        for s0, s1, v in self._spread_figures()[2]:
            if s0 <= end and start <= s1:
                u = max(u, v)
        return u

    def latest_between(self, start: float, end: float, horizon: float = 1.0) -> float:
        """:meth:`between` for a stamp just made, from the taints of the last ``horizon``
        seconds only (they are kept in arrival order): a listener stamps every byte with its
        local figure, and scanning a whole day's taints per byte would not keep up."""
        recent = takewhile(lambda t: t.end >= start - horizon, reversed(self.taints))
        return _worst_taint(recent, start, end, self.uncertainty())

    @property
    def reference(self) -> str:
        return "echo" if self.echo else "write"

    def observed(self) -> float:
        """The worst observed error of a stamp difference anywhere in the run (s)."""
        seen = [self.echo_spread.value, self.batches.value, self.artefacts.value]
        if not self.kernel_stamps:
            seen.append(self.reader_lag.value)
        return max(seen)

    def regular(self) -> float:
        """The error every stamp may have, stalls aside (s): the regular echo spread, and
        the reader's lateness where the stamps are the reader's own."""
        seen = [self.regular_spread()]
        if not self.kernel_stamps:
            seen.append(self.reader_lag.value)
        return max(seen)

    def uncertainty(self) -> float:
        """What a timing finding with no local irregularity uses: the floor of the reference,
        the regular observed error, the user's figure; whichever is largest."""
        floor = ECHO_FLOOR if self.echo else self.declared
        return max(floor, self.regular(), self.widen_to)

    def samples(self) -> int:
        return (
            self.echo_spread.count
            + self.batches.count
            + self.artefacts.count
            + self.reader_lag.count
        )

    def summary(self) -> str:
        """One line for reports: how the figure was arrived at."""
        u = self.uncertainty()
        worst = self.observed()
        text = (
            f"measured ±{u * 1e3:.2f} ms ({self.samples()} samples, worst {worst * 1e3:.2f} ms; "
            f"timed against the {'echo of the command' if self.echo else 'write time'}"
        )
        floor = ECHO_FLOOR if self.echo else self.declared
        if u == floor and floor > self.regular():
            text += f", declared floor {floor * 1e3:.2f} ms"
        if self.taints:
            text += f"; {len(self.taints)} local irregularities widen the stamps near them"
        if self.widen_to and u == self.widen_to:
            text += ", widened by --timing-uncertainty-ms"
        return text + ")"

    def to_json(self) -> dict[str, object]:
        def part(w: Worst) -> dict[str, object]:
            return {"worst_ms": round(w.value * 1e3, 3), "samples": w.count, "where": w.where}

        return {
            "reference": self.reference,
            "uncertainty_ms": round(self.uncertainty() * 1e3, 3),
            "declared_floor_ms": round((ECHO_FLOOR if self.echo else self.declared) * 1e3, 3),
            "kernel_stamps": self.kernel_stamps,
            "echo_spread": part(self.echo_spread),
            "batches": part(self.batches),
            "artefacts": part(self.artefacts),
            "reader_lag": part(self.reader_lag),
            "round_trip": part(self.round_trip),
            "turnaround": part(self.turnaround),
            "regular_ms": round(self.regular() * 1e3, 3),
            "local_irregularities": len(self.taints),
            "summary": self.summary(),
        }


class _TaintIndex:
    """Taints ordered by start, for :meth:`TimingMeter.between`: only those that start
    between ``start`` less the longest taint and ``end`` can touch ``start..end``."""

    #: s of slack on the lower cut: a taint the float arithmetic puts just outside is still
    #: checked (checking more never changes the answer, missing one would)
    SLACK = 1e-6

    def __init__(self, taints: Sequence[Taint]) -> None:
        self.count = len(taints)
        self.ordered = sorted(taints[: self.count], key=lambda t: t.start)
        self.starts = [t.start for t in self.ordered]
        self.longest = max((t.end - t.start for t in self.ordered), default=0.0)

    def worst(self, start: float, end: float, u: float) -> float:
        lo = bisect_left(self.starts, start - max(self.longest, 0.0) - self.SLACK)
        hi = bisect_right(self.starts, end)
        return _worst_taint(self.ordered[lo:hi], start, end, u)


def _worst_taint(taints: Iterable[Taint], start: float, end: float, u: float) -> float:
    """``u``, or the largest error of the taints that touch ``start..end``."""
    for t in taints:
        if t.start <= end and start <= t.end:
            u = max(u, t.error)
    return u
