"""Timing as metrology (design.md section 4): a measured interval with its uncertainty
against a limit, giving PASS, FAIL or an honest INCONCLUSIVE.

PASS only when the whole interval ``measured +/- uncertainty`` lies inside the allowed window
(widened by the spec's tolerance), FAIL only when the whole interval lies outside it.
"""

from __future__ import annotations

from array import array
from bisect import bisect_right
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property
from itertools import accumulate, chain, repeat
from math import copysign
from statistics import median
from typing import Generic, Protocol, TypeVar

from ..links.host_stall import Stall
from ..preconditions import awake
from ..protocol.timing import STANDBY_MARKING, TOLERANCE
from ..verdicts import MAX_TICKS, Distribution, Finding, Verdict

EPSILON = 1e-9  # s: a value exactly on a limit is inside it, whatever float rounding says

#: the verdicts the measurements compare with, as module constants: a member read off the
#: enum on Python 3.11 goes through its metaclass's ``__getattr__`` hook (issue 22, matrix25:
#: ~0.13 us a look, every measured interval of a run looked three times)
_PASS, _WARN, _FAIL, _INCONCLUSIVE = Verdict.PASS, Verdict.WARN, Verdict.FAIL, Verdict.INCONCLUSIVE


def not_listening(rid: str, marking: float, uncertainty: float) -> Finding | None:
    """The precondition of a silence-based FAIL on a wake-up or break rule (issue 18,
    :func:`conformance.preconditions.awake`): the command went out while a compliant sensor
    must still be listening. INCONCLUSIVE naming the measured marking when it did not; None
    when the precondition holds."""
    unmet = awake(marking, uncertainty)
    if unmet is None:
        return None
    found = unmet.finding(rid)
    found.measured_ms = round(marking * 1e3, 3)
    found.limit_ms = round(STANDBY_MARKING * 1e3, 3)
    found.uncertainty_ms = round(uncertainty * 1e3, 3)
    return found


@dataclass(frozen=True)
class StampUncertainty:
    """A run's timing uncertainty: ``base`` everywhere, more where the link saw its own
    stamps irregular (``local(start, end)``, real links; a virtual clock has none)."""

    base: float
    local: Callable[[float, float], float] | None = None

    def between(self, start: float, end: float) -> float:
        if self.local is None:
            return self.base
        return max(self.base, self.local(start, end))


def stamp_uncertainty(u: float | StampUncertainty) -> StampUncertainty:
    return u if isinstance(u, StampUncertainty) else StampUncertainty(u)


MIN_DEVIATING = 2  # real-time links: deviating observations a FAIL needs at least...
MIN_SHARE = 0.05  # ...and at least this share of all observations
#: Observations of one place (the same command's reply, the same character) that decide
#: whether a rare deviation there recurs: fewer leave it to be re-probed (issue 18).
CONFIRM_OBSERVATIONS = 6
#: How often a whole-run case sends a command again to confirm a deviation in its reply.
REPROBE_TIMES = 10

#: Where an observation fell: the command, the reply it is in (its text: the same command
#: may read other data another time, and only the same reply shows the same point again)
#: and the position in that reply (a character index; 0 for the reply's start). None: no
#: place known.
Place = tuple[str, str, int]
#: One judged observation: a :class:`Finding`, or a :class:`Measured` that builds it on demand;
#: whether it is tainted (a local irregularity of the stamps, or the host stall read across)
Observation = (
    tuple["Finding | Measured", "bool | Stall"]
    | tuple["Finding | Measured", "bool | Stall", Place | None]
)


def sustained(deviating: int, total: int) -> bool:
    """Whether deviations are frequent enough on a real-time link to be the device's."""
    return deviating >= MIN_DEVIATING and deviating >= MIN_SHARE * total


@dataclass(frozen=True)
class Pattern:
    """Where a real-time link's few deviating observations fall (issue 18). A host that
    stalls does so at random moments; a device deviates at the same point of the same reply.
    Per place with a deviation, once it was observed :data:`CONFIRM_OBSERVATIONS` times or
    more: ``recurring`` (at least :data:`MIN_DEVIATING` deviations there and at least half
    of its observations: the device's) or ``not_reproduced`` (a single one: a stall); else
    ``unconfirmed`` (too few observations of that place to tell, or several deviations but
    fewer than half: the command wants re-probing, or stays undecided)."""

    recurring: dict[Place, tuple[int, int]]
    not_reproduced: dict[Place, tuple[int, int]]
    unconfirmed: dict[Place | None, tuple[int, int]]

    @property
    def commands(self) -> list[str]:
        """The commands to send again, in first-seen order."""
        return list(dict.fromkeys(p[0] for p in self.unconfirmed if p is not None))


def deviation_pattern(observed: list[tuple[Finding | Measured, Place | None]]) -> Pattern:
    """:class:`Pattern` of the FAILing observations among ``observed``."""
    counts: dict[Place | None, list[int]] = {}
    for finding, place in observed:
        seen = counts.setdefault(place, [0, 0])
        seen[1] += 1
        seen[0] += finding.verdict is _FAIL
    recurring, stalls, unconfirmed = {}, {}, {}
    for place, (bad, total) in counts.items():
        if not bad:
            continue
        if place is None or total < CONFIRM_OBSERVATIONS:
            unconfirmed[place] = (bad, total)
        elif bad >= MIN_DEVIATING and 2 * bad >= total:
            recurring[place] = (bad, total)
        elif bad < MIN_DEVIATING:
            stalls[place] = (bad, total)
        else:
            unconfirmed[place] = (bad, total)
    return Pattern(recurring, stalls, unconfirmed)


def _places(observed: list[Observation]) -> list[tuple[Finding | Measured, bool, Place | None]]:
    return [(o[0], o[1], o[2] if len(o) > 2 else None) for o in observed]  # type: ignore[misc]


def to_confirm(observed: list[Observation], *, real_time: bool = True) -> list[str]:
    """The commands whose replies hold a rare deviation :func:`combine_local` cannot yet
    place: the session sends each again (:data:`REPROBE_TIMES`) and the judge runs again over
    the repeats. Empty on a virtual clock, or when the deviations are not rare. And those
    whose reply deviated only across a stall of the tool's own host, where that reply was not
    observed outside one often enough to stand for it (:func:`_stalled_unconfirmed`)."""
    if not real_time:
        return []
    placed = _places(observed)
    stalled = [p[0] for p in _stalled_unconfirmed(placed) if p is not None]
    kept = [(f, p) for f, tainted, p in placed if not _aside(f, tainted)]
    failing = sum(f.verdict is _FAIL for f, _ in kept)
    if failing and (failing == len(kept) or sustained(failing, len(kept))):
        return []  # a FAIL on what was read outside any stall: nothing a repeat would change
    if not failing:
        return list(dict.fromkeys(stalled))
    return list(dict.fromkeys(deviation_pattern(kept).commands + stalled))


def _stalled_unconfirmed(
    placed: list[tuple[Finding | Measured, bool | Stall, Place | None]],
) -> list[Place | None]:
    """The places of the deviations set aside as read across a stall of the tool's own host
    (an observation tainted by its :class:`~conformance.links.host_stall.Stall`,
    :func:`~.stalled.stalled_interval`) that the observations kept there, outside any
    stall, are too few (:data:`CONFIRM_OBSERVATIONS`) to stand for: a device late at that
    one reply alone would otherwise PASS for the stall's sake (truth29)."""
    held = [p for f, t, p in placed if type(t) is Stall and _aside(f, t)]
    if not held:
        return []
    seen = Counter(p for f, t, p in placed if not _aside(f, t))
    return [p for p in dict.fromkeys(held) if p is None or seen[p] < CONFIRM_OBSERVATIONS]


def _aside(f: Finding | Measured, tainted: bool | Stall) -> bool:
    return tainted and f.verdict is _INCONCLUSIVE


def _where(place: Place) -> str:
    command, _reply, index = place
    return f"reply to {command}" + (f", character {index}" if index else "")


def combine_local(
    rid: str,
    observed: list[Observation],
    what: str,
    *,
    smallest_is_worst: bool = False,
    real_time: bool = True,
) -> Finding:
    """:func:`combine` for observations each judged with its own uncertainty, flagged where
    that was widened by a local irregularity of the link's stamps, and optionally placed
    (``(finding, tainted, place)``: which command's reply, which character).

    - An observation that the irregularity alone left undecided says nothing about the DUT:
      it is set aside (and counted in the detail) instead of making the whole rule
      INCONCLUSIVE. If every observation was set aside the rule stays INCONCLUSIVE.
    - So is a deviation whose stamps a noted stall of the tool's own host may have moved
      (tainted by that :class:`~conformance.links.host_stall.Stall`:
      :func:`~.stalled.stalled_interval`), the stall named; where the observations kept at
      its place are too few to stand for it, a PASS is INCONCLUSIVE (truth29) and the
      session observes that reply again (:func:`to_confirm`).
    - On a real-time link (``real_time``) a host that stalls can make a stamp late with no
      trace around it (the last character of a reply has no successor to show it); a few
      deviating observations among many that conform are therefore decided by where they
      fall (:func:`deviation_pattern`): recurring at the same place, they are the device's
      and judged as measured (FAIL); alone at a place observed often enough otherwise, they
      are host stalls and set aside (named in the detail); where the place was not observed
      often enough to tell, the rule is INCONCLUSIVE (the session re-probes those commands,
      :func:`to_confirm`, and the judge runs again over the repeats). Many deviations
      (:func:`sustained`) are a FAIL as they are. On a virtual clock every observation is
      exact and one is enough."""
    # a run's character gaps number tens of thousands, nearly always none tainted (never on
    # a virtual clock): then every one is kept, as one slice; the places are wanted only by
    # the few deviations of a real-time link (_by_place), and gathered only then
    kept: Sequence[Finding | Measured]
    stalled: list[Place | None] = []  # the places a stall alone leaves unconfirmed
    note = ""
    if type(observed) is Observed:  # none tainted, grouped as they were made
        kept, aside = Alike(observed), []
    elif any(o[1] for o in observed):
        kept = [o[0] for o in observed if not _aside(o[0], o[1])]
        aside = [o[0] for o in observed if _aside(o[0], o[1])]
        note = _aside_note(observed, what)
        stalled = _stalled_unconfirmed(_places(observed))
    else:
        kept, aside = [o[0] for o in observed], []
    if aside and not kept:
        return Finding(rid, _INCONCLUSIVE, f"every {what} undecided; {note}")
    failing = kept.failing() if type(kept) is Alike else sum(f.verdict is _FAIL for f in kept)
    isolated = real_time and failing and failing < len(kept) and not sustained(failing, len(kept))
    if isolated:
        places = [o[2] if len(o) > 2 else None for o in observed if not _aside(o[0], o[1])]  # type: ignore[misc]
        found = _by_place(rid, list(zip(kept, places, strict=True)), what, smallest_is_worst)
    else:
        found = combine(rid, kept, what, smallest_is_worst=smallest_is_worst)
    if aside:
        found.detail += f"; {note}"
    if stalled and found.verdict is _PASS:
        found = _unconfirmed_across_stall(found, stalled, what)
    # the figures the verdict rests on (combine() drew them already when it saw them all);
    # what the link's irregular stamps set aside is counted
    if isolated:
        found.distribution = distribution(kept)
    if found.distribution is not None:
        found.distribution.set_aside = len(aside)
    return found


def _aside_note(observed: list[Observation], what: str) -> str:
    """What :func:`combine_local` says of the observations it set aside: those the link's
    irregular stamps left undecided, and those read across a stall of the tool's own host
    (tainted by the :class:`~conformance.links.host_stall.Stall`), the first named."""
    aside = [(o[0], o[1]) for o in observed if _aside(o[0], o[1])]
    irregular = [f for f, t in aside if type(t) is not Stall]
    held = [f for f, t in aside if type(t) is Stall]
    notes = []
    if irregular:
        worst_aside = max((f.uncertainty_ms or 0.0 for f in irregular), default=0.0)
        notes.append(
            f"{counted(len(irregular), what)} set aside: the link's "
            f"stamps near them were irregular (±{worst_aside:.2f} ms there)"
        )
    if held:
        first = held[0]
        where = f" [{first.evidence[0]}]" if first.evidence else ""
        notes.append(
            f"{counted(len(held), what)} set aside, read across a stall of the tool's own "
            f"host, such as: {first.detail}{where}"
        )
    return "; ".join(notes)


def _unconfirmed_across_stall(found: Finding, places: list[Place | None], what: str) -> Finding:
    """``found`` (a PASS) INCONCLUSIVE: a deviation read across a host stall is at
    ``places`` the conforming observations there do not show often enough to stand for
    (:func:`_stalled_unconfirmed`)."""
    said = ", ".join(_where(p) if p is not None else "an unplaced one" for p in places[:3])
    found.verdict = _INCONCLUSIVE
    found.detail += (
        f"; but the deviating {plural(what)} read across a stall of the tool's host at "
        f"{said} were not observed outside a stall often enough "
        f"({CONFIRM_OBSERVATIONS} times) to tell: not decided"
    )
    return found


def _by_place(
    rid: str,
    kept: list[tuple[Finding | Measured, Place | None]],
    what: str,
    smallest_is_worst: bool,
) -> Finding:
    """The few deviations of :func:`combine_local` on a real-time link, decided by place."""
    pattern = deviation_pattern(kept)
    failing = [f for f, _ in kept if f.verdict is _FAIL]
    if pattern.recurring:
        device = [f for f, p in kept if f.verdict is not _FAIL or p in pattern.recurring]
        found = combine(rid, device, what, smallest_is_worst=smallest_is_worst)
        said = "; ".join(
            f"{bad} of {total} at {_where(p)}" for p, (bad, total) in pattern.recurring.items()
        )
        found.detail += (
            f"; the deviations recur at the same point of the same reply ({said}): the "
            "device's, not stalls of the host, which fall at random"
        )
        others = len(failing) - sum(bad for bad, _ in pattern.recurring.values())
        if others:
            found.detail += f"; {others} other deviating {plural(what)} not counted"
        return found
    if not pattern.unconfirmed:
        rest = [f for f, _ in kept if f.verdict is not _FAIL]
        found = combine(rid, rest, what, smallest_is_worst=smallest_is_worst)
        lone = failing[0]
        said = "; ".join(
            f"{bad} of {total} at {_where(p)}" for p, (bad, total) in pattern.not_reproduced.items()
        )
        found.detail += (
            f"; {len(failing)} deviating {plural(what) if len(failing) != 1 else what} set "
            f"aside as stalls of the host, such as {lone.detail}: each alone at its place, "
            f"not reproduced when that reply was observed again ({said})"
        )
        return found
    lone = failing[0]
    others = [f for f, _ in kept if f.verdict is not _FAIL]
    rest = combine(rid, others, what, smallest_is_worst=smallest_is_worst)
    where = f" [{lone.evidence[0]}]" if lone.evidence else ""
    return Finding(
        rid,
        _INCONCLUSIVE,
        f"{len(failing)} of {len(kept)} {plural(what)} deviate, such as: {lone.detail}"
        f"{where}; the others conform ({rest.detail}). Deviations this rare on a "
        "real-time link may be stalls of the host, not of the device, and they were not "
        "observed again at the same place often enough to tell: not decided",
        measured_ms=lone.measured_ms,
        limit_ms=lone.limit_ms,
        uncertainty_ms=lone.uncertainty_ms,
        evidence=lone.evidence,
        observed=len(kept),
    )


def judge_window(
    requirement: str,
    what: str,
    measured: float,
    uncertainty: float,
    *,
    low: float | None = None,
    high: float | None = None,
    tolerance: float = TOLERANCE,
    should: bool = False,
    evidence: list[str] | None = None,
    decision: str | None = None,
) -> Finding:
    """Judge ``measured`` (s) against ``[low - tol, high + tol]``.

    ``should`` turns a definite violation into WARN (a SHOULD rule or a lenient decision).
    """
    window = Window(requirement, what, low, high, tolerance, should, decision)
    return window.judge(measured, uncertainty, evidence)


@dataclass(frozen=True)
class Window:
    """The limits :func:`judge_window` applies, worked out once for the many intervals a
    whole-run rule judges against them (tens of thousands of character gaps in a run)."""

    requirement: str
    what: str
    low: float | None = None
    high: float | None = None
    tolerance: float = TOLERANCE
    should: bool = False
    decision: str | None = None

    @cached_property
    def lo(self) -> float | None:
        return None if self.low is None else self.low - self.tolerance - EPSILON

    @cached_property
    def hi(self) -> float | None:
        return None if self.high is None else self.high + self.tolerance + EPSILON

    def inside(self, measured: float) -> bool:
        """Whether ``measured`` is within the limits, taken as exact."""
        return _slack(self.lo, self.hi, measured) >= 0

    def judge(
        self, measured: float, uncertainty: float, evidence: list[str] | None = None
    ) -> Finding:
        """The whole finding, detail text and all (:func:`judge_window`)."""
        lo, hi = self.lo, self.hi
        verdict, outside = _window_verdict(lo, hi, measured, uncertainty, self.should)
        limit = _describe_limit(lo, hi)
        detail = (
            f"{self.what}: {measured * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} ms, allowed {limit}"
        )
        if verdict is _INCONCLUSIVE:
            detail += " (the uncertainty straddles the limit)"
        limit_ms = (hi if hi is not None else lo) or 0.0
        return Finding(
            self.requirement,
            verdict,
            detail,
            measured_ms=round(measured * 1e3, 3),
            limit_ms=round(limit_ms * 1e3, 3),
            uncertainty_ms=round(uncertainty * 1e3, 3),
            evidence=list(evidence or []),
            decision=self.decision,
            margin_ms=_margin_ms(lo, hi, measured, outside),
            observed=1,  # one measured interval between two observed wire events
            distribution=_single(measured, uncertainty, lo, hi),
        )


def _slack(lo: float | None, hi: float | None, measured: float) -> float:
    """Distance (s) from ``measured`` to its nearer edge, negative when outside."""
    edges = [e for e in (None if lo is None else measured - lo,
                         None if hi is None else hi - measured) if e is not None]  # fmt: skip
    return min(edges) if edges else 0.0


def _ms(seconds: float | None) -> float | None:
    return None if seconds is None else round(seconds * 1e3, 3) + 0.0  # never -0.0


def _single(
    measured: float, uncertainty: float, lo: float | None, hi: float | None
) -> Distribution:
    value = round(measured * 1e3, 3)
    slack = round(_slack(lo, hi, measured) * 1e3, 3)
    return Distribution(1, value, value, value, _ms(lo), _ms(hi), round(uncertainty * 1e3, 3),
                        slack, values_ms=[value], slack_ms=[slack])  # fmt: skip


#: a distribution's figures in seconds as :func:`distribution` gathers them: values, slacks,
#: edges (ms), uncertainty, count
_Seconds = tuple[list[float], list[float], tuple[float | None, float | None], float, int]


def _in_seconds(d: Distribution) -> _Seconds:
    return (
        [v / 1e3 for v in d.values_ms],
        [v / 1e3 for v in d.slack_ms],
        (d.low_ms, d.high_ms),
        d.uncertainty_ms / 1e3,
        d.count,
    )


def distribution(observations: Sequence[Finding | Measured]) -> Distribution | None:
    """Every measurement of ``observations`` as one :class:`Distribution` (None when none
    was judged against a window): what the margins chart and ``verdicts.json`` show.

    One pass in seconds, rounded to ms only for what is kept: a run's character gaps number
    tens of thousands, nearly all judged against one window, and most of them are the same
    few hundred :class:`Measured` (equal gaps of one reply judged once: ``judges/wire``), so
    those are figured once each (:func:`_distribution_of_one_window`)."""
    grouped = _grouped(observations)
    if grouped is not None:
        return _distribution_of_one_window(*grouped, len(observations))
    tallied = _tallied(observations)
    figured = None if tallied is None else _distribution_of_tallies(tallied)
    if figured is not None:
        return figured
    values: list[float] = []  # s
    slacks: list[float] = []  # s
    uncertainties: list[float] = []  # s
    edges: set[tuple[float | None, float | None]] = set()
    count = 0
    window = None
    lo = hi = None
    # an object that comes again gives the same figures: made once, the same floats again
    again: dict[int, _Seconds] = {}
    for o in observations:
        if type(o) is Measured:
            if o._window is not window:
                window = o._window
                lo, hi = window.lo, window.hi
                edges.add((_ms(lo), _ms(hi)))
            m = o.measured
            values.append(m)
            slacks.append(_slack(lo, hi, m))
            uncertainties.append(o.uncertainty)
            count += 1
        else:
            made = again.get(id(o))
            if made is None:
                d = o.distribution
                if d is None:
                    continue
                made = again[id(o)] = _in_seconds(d)
            d_values, d_slacks, d_edges, d_uncertainty, d_count = made
            values.extend(d_values)
            slacks.extend(d_slacks)
            edges.add(d_edges)
            uncertainties.append(d_uncertainty)
            count += d_count
    if not values:
        return None
    total = sum(values) + sum(slacks) + sum(uncertainties)
    if total != total:  # a NaN among them (or infinities that cancel): each sorted last
        order = sorted(range(len(values)), key=lambda i: _nan_last(values[i]))
        least_slack = min(slacks, key=_nan_last)
        u_mid = _median_nan_last(uncertainties)
    else:
        order = sorted(range(len(values)), key=values.__getitem__)
        least_slack, u_mid = min(slacks), median(uncertainties)
    kept = [order[p] for p in _tick_positions(len(order))]
    low, high = next(iter(edges)) if len(edges) == 1 else (None, None)
    middle = len(order) // 2
    mid = (
        values[order[middle]]
        if len(order) % 2
        else (values[order[middle - 1]] + values[order[middle]]) / 2
    )
    return Distribution(
        count,
        _ms(values[order[0]]) or 0.0,
        _ms(mid) or 0.0,
        _ms(values[order[-1]]) or 0.0,
        low,
        high,
        _ms(u_mid) or 0.0,  # typical: a few stamps near a stall are far wider
        _ms(least_slack) or 0.0,
        mixed_limits=len(edges) > 1,
        values_ms=[_ms(values[i]) or 0.0 for i in kept],
        slack_ms=[_ms(slacks[i]) or 0.0 for i in kept],
    )


def _nan_last(v: float) -> tuple[bool, float]:
    """A sort key that puts a NaN after every number, the NaNs in the order they came: a
    distribution of observations that hold one is then a function of their values, not of
    their order (``sorted`` compares a NaN false with everything, so it stayed where the
    order put it and moved the others around it), which a fold that counts them without
    their order (:class:`Observed` not placed) must give the same. Without a NaN the order
    is ``sorted``'s own."""
    return (v != v, v)


def _median_nan_last(values: list[float]) -> float:
    """``statistics.median`` of ``values`` sorted by :func:`_nan_last`."""
    ordered = sorted(values, key=_nan_last)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else (ordered[middle - 1] + ordered[middle]) / 2


#: :func:`_tallied` gives up past this many distinct objects (then one by one is as small)
TALLIED_MAX = 4096


def _tallied(observations: Sequence[Finding | Measured]) -> list[tuple[_Seconds, int]] | None:
    """``observations`` as each distinct object's figures (:data:`_Seconds`; left out where
    it has no distribution) and how often it comes, in the order each first comes: what
    :func:`distribution` reads one by one where the objects are not all plain
    :class:`Measured` against one window (the recorder's breaks and command character gaps,
    :class:`MeasuredAsJudged`: an hour's 180,000 gaps made three lists, a sort order and a
    median's copy of that length, 7 MB at the recorder run's peak, memory20). None past
    :data:`TALLIED_MAX` distinct objects."""
    times: dict[int, int] = {}
    made: dict[int, _Seconds | None] = {}
    for o in observations:
        k = id(o)
        n = times.get(k)
        if n is not None:
            times[k] = n + 1
            continue
        if len(times) == TALLIED_MAX:
            return None
        times[k] = 1
        if type(o) is Measured:
            lo, hi = o._window.lo, o._window.hi
            m = o.measured
            made[k] = ([m], [_slack(lo, hi, m)], (_ms(lo), _ms(hi)), o.uncertainty, 1)
        else:
            d = o.distribution
            made[k] = None if d is None else _in_seconds(d)
    return [(f, times[k]) for k, f in made.items() if f is not None]


def _distribution_of_tallies(tallies: list[tuple[_Seconds, int]]) -> Distribution | None:
    """:func:`distribution` of figures each ``times`` over (:func:`_tallied`): the same
    figures as one by one, worked out from each distinct value and how often it comes (the
    sorted position found by the running counts, :func:`_sorted_positions`). One by one
    picks, among equal values, the slack of the first in the observations' order; here
    every equal value must have one slack (one window), else None (one by one then), as
    where a figure is not a number."""
    counts: dict[float, int] = {}  # value (s) -> how many
    slack_of: dict[float, float] = {}
    u_counts: dict[float, int] = {}  # uncertainty (s) -> how many
    edges: set[tuple[float | None, float | None]] = set()
    count = 0
    for (values, slacks, d_edges, u, d_count), times in tallies:
        if u != u:
            return None
        edges.add(d_edges)
        u_counts[u] = u_counts.get(u, 0) + times
        count += d_count * times
        for v, s in zip(values, slacks, strict=True):
            if v != v or s != s or slack_of.setdefault(v, s) != s:
                return None
            counts[v] = counts.get(v, 0) + times
    if not counts:
        return None
    distinct = list(counts)
    n = sum(counts.values())
    values_sorted, at = _sorted_positions(distinct, [counts[v] for v in distinct])
    ticks = [at(p) for p in _tick_positions(n)]
    us = list(u_counts)
    u_at = _sorted_positions(us, [u_counts[u] for u in us])[1]
    low, high = next(iter(edges)) if len(edges) == 1 else (None, None)
    return Distribution(
        count,
        _ms(values_sorted[0]) or 0.0,
        _ms(_median_of_positions(at, n)) or 0.0,
        _ms(values_sorted[-1]) or 0.0,
        low,
        high,
        _ms(_median_of_positions(u_at, sum(u_counts.values()))) or 0.0,
        _ms(min(slack_of.values())) or 0.0,
        mixed_limits=len(edges) > 1,
        values_ms=[_ms(v) or 0.0 for v in ticks],
        slack_ms=[_ms(slack_of[v]) or 0.0 for v in ticks],
    )


def _grouped(
    observations: Sequence[Finding | Measured],
) -> tuple[Window, list[Measured], list[int]] | None:
    """``observations`` as each distinct object and how often it comes, in the order each
    first comes, where every one is a plain :class:`Measured` against the one window (the
    same object); None otherwise (or none at all): :func:`distribution` then goes one by
    one. An object says the same each time it comes, so its figures stand for every time."""
    if type(observations) is Alike:
        return observations.grouped()
    first = observations[0] if observations else None
    if type(first) is not Measured:
        return None
    window = first._window
    at: dict[int, int] = {}  # id -> index in distinct
    distinct: list[Measured] = []
    counts: list[int] = []
    for o in observations:
        i = at.get(id(o))
        if i is not None:
            counts[i] += 1
            continue
        if type(o) is not Measured or o._window is not window:
            return None
        if o.measured != o.measured or o.uncertainty != o.uncertainty:
            return None  # a NaN sorts by where it stands: one by one
        at[id(o)] = len(distinct)
        distinct.append(o)  # type: ignore[arg-type]
        counts.append(1)
    return window, distinct, counts


class Alike(Sequence["Measured"]):
    """The findings of untainted observations (:class:`Observed`), each distinct object with
    how often it comes, in the order each first comes: what :func:`combine` and
    :func:`distribution` would otherwise work out again from the tens of thousands of a
    run's character gaps (``{id(f): f}``, :func:`_grouped`). Reads as the sequence of the
    observations' findings, one by one, where something needs them so."""

    __slots__ = ("_observed", "counts", "distinct")

    def __init__(self, observed: Observed) -> None:
        self._observed = observed
        self.distinct = observed.distinct
        self.counts = observed.counts

    def __len__(self) -> int:
        return len(self._observed)

    def __getitem__(self, i):  # type: ignore[no-untyped-def,override]
        picks, distinct = self._observed._picks, self.distinct
        if picks is None:  # counted: in the order each first came (Observed)
            if isinstance(i, slice):
                return list(self)[i]
            return self._observed.counted_at(range(len(self))[i])
        if isinstance(i, slice):
            return [distinct[k] for k in picks[i]]
        return distinct[picks[i]]

    def __iter__(self) -> Iterator[Measured]:
        return self._observed.findings()

    def failing(self) -> int:
        """How many of them FAIL."""
        return sum(c for m, c in zip(self.distinct, self.counts, strict=True)
                   if m.verdict is _FAIL)  # fmt: skip

    def grouped(self) -> tuple[Window, list[Measured], list[int]] | None:
        """:func:`_grouped` of the findings, from the groups: the same answer."""
        if not self.distinct or type(self.distinct[0]) is not Measured:
            return None  # (a finding among them, counted: timing.Counted)
        window = self.distinct[0]._window
        for m in self.distinct:
            if type(m) is not Measured or m._window is not window:
                return None
            if m.measured != m.measured or m.uncertainty != m.uncertainty:
                return None  # a NaN sorts by where it stands: one by one
        return window, self.distinct, self.counts


class Observed(Sequence["tuple[Measured, bool, Place | None]"]):
    """Observations ``(measured, False, place)``, none tainted, made in one pass with their
    :class:`Measured` objects grouped (``distinct``, each first where it first comes, and
    ``counts``: ``judges/wire``'s equal gaps judged once). :func:`combine_local` then reads
    the groups instead of passing over every observation again.

    Held compact (issue 22: an hour of a busy bus is 25,000 character gaps a sensor, a
    list of a tuple and a place tuple each ~5 MB): each observation is the index of its
    object in ``distinct``, and its place the index of its ``(command, reply)`` among those
    seen with the character's index, 12 bytes in three arrays; read one by one it gives the
    same tuples (equal places, the same objects).

    Not ``placed`` (counted): where nothing reads the observations' places or order, only
    the groups (a recording judged on one uncertainty for every stamp, with no stalls of the
    tool's host: :func:`combine_local` then reads neither, since it decides no deviation by
    place and sets none aside), nothing is held per observation but their number (memory24:
    the indexes were 12 bytes a gap, 24 a reply, and the places held every distinct reply
    text of the run). Read one by one it gives each distinct object ``counts`` times in the
    order each first came, each place None: what :func:`distribution` reads of them does
    not depend on their order (its one-by-one path sorts a NaN last, :func:`_nan_last`), so
    the findings are those of the observations as they came. Only where no observation can
    be tainted either: a tainted one turns :class:`~.wire._FoldedStarts` into the list in
    order, which a counted fold no longer has."""

    __slots__ = ("_at", "_n", "_picks", "_replies", "_replies_seen", "_spots", "counts",
                 "distinct")  # fmt: skip

    def __init__(self, placed: bool = True) -> None:
        self.distinct: list[Measured] = []
        self.counts: list[int] = []
        self._n = 0  # how many observations (the arrays' length where placed)
        # each observation's index in distinct, its index in _replies and its character
        # index (a place's third part); None: counted, not placed
        self._picks = array("I") if placed else None
        self._spots = array("I") if placed else None
        self._at = array("I") if placed else None
        self._replies: list[tuple[str, str] | None] = []
        self._replies_seen: dict[tuple[str, str] | None, int] = {}

    @property
    def placed(self) -> bool:
        """Whether each observation's place (and order) is held, not only counted."""
        return self._picks is not None

    def _spot(self, reply: tuple[str, str] | None) -> int:
        spot = self._replies_seen.get(reply)
        if spot is None:
            spot = self._replies_seen[reply] = len(self._replies)
            self._replies.append(reply)
        return spot

    def observe(self, i: int, place: Place | None) -> None:
        """One more observation: ``distinct[i]`` at ``place`` (not held where counted; the
        caller counts it in ``counts``)."""
        self._n += 1
        if self._picks is None:
            return
        self._picks.append(i)
        self._spots.append(self._spot(None if place is None else (place[0], place[1])))  # type: ignore[union-attr]
        self._at.append(0 if place is None else place[2])  # type: ignore[union-attr]

    def observe_run(self, picks: list[int], reply: tuple[str, str], first: int) -> None:
        """:meth:`observe` of ``distinct[i]`` for each ``i`` of ``picks``, at places
        ``(*reply, first)``, ``(*reply, first + 1)``..: a reply's consecutive character gaps
        taken at once (issue 22, matrix19: the arrays extended in C, not a call a gap, some
        20,000 a run)."""
        n = len(picks)
        self._n += n
        if self._picks is None:
            return
        spot = self._spot(reply)
        self._picks.fromlist(picks)
        self._spots.fromlist([spot] * n)  # type: ignore[union-attr]
        self._at.fromlist(list(range(first, first + n)))  # type: ignore[union-attr]

    def __len__(self) -> int:
        return self._n

    def _one(self, n: int) -> tuple[Measured, bool, Place | None]:
        if self._picks is None:
            return self.counted_at(n), False, None
        reply = self._replies[self._spots[n]]  # type: ignore[index]
        place = None if reply is None else (reply[0], reply[1], self._at[n])  # type: ignore[index]
        return self.distinct[self._picks[n]], False, place

    def counted_at(self, n: int) -> Measured:
        """Counted: the ``n``-th (0 <= n < len) of the objects each ``counts`` times in the
        order each first came, found by walking the counts (the distinct ones, not every
        observation: a list of them made per index was quadratic over a loop)."""
        for m, count in zip(self.distinct, self.counts, strict=True):
            if n < count:
                return m
            n -= count
        raise IndexError("observation index out of range")

    def __getitem__(self, n):  # type: ignore[no-untyped-def,override]
        if isinstance(n, slice):
            return [self._one(k) for k in range(*n.indices(len(self)))]
        return self._one(range(len(self))[n])

    def __iter__(self) -> Iterator[tuple[Measured, bool, Place | None]]:
        if self._picks is None:
            return ((m, False, None) for m in self.findings())
        return (self._one(n) for n in range(len(self)))

    def findings(self) -> Iterator[Measured]:
        """Each observation's object, in order (no place made); counted: each distinct
        object ``counts`` times, in the order each first came."""
        distinct = self.distinct
        if self._picks is None:
            return chain.from_iterable(map(repeat, distinct, self.counts))
        return (distinct[i] for i in self._picks)


class Counted:
    """A rule's judged observations appended one at a time (a recorder fold's breaks,
    markings and command character gaps, :mod:`.recorder`), held as each distinct object
    and how often it comes, in the order each first came (an :class:`Observed` not placed),
    not a list of them: :meth:`alike` is what :func:`combine` reads, with the same finding
    (the first of the worst, each object's ``observed`` counted, the same distribution:
    :func:`_tallied` groups by object in first-come order, and the one-by-one path is a
    function of the values, :func:`_nan_last`). A list held one pointer an observation:
    an hour of a busy bus's 45,000 command character gaps and 15,000 breaks and markings,
    0.6 MB at the recorder pass's end and 2.5 MB at four hours (memory26); this holds
    the distinct objects (the folds judge an equal interval once, :class:`Repeats`).

    Only where nothing reads the observations' order: each distinct object must say the
    same at every place it comes (a finding, a :class:`Measured` of one window)."""

    __slots__ = ("_index", "observed")

    def __init__(self) -> None:
        self.observed = Observed(placed=False)
        self._index: dict[int, int] = {}  # id of a distinct object -> its index

    def append(self, judged: Finding | Measured) -> None:
        """One more observation, ``judged``."""
        observed = self.observed
        i = self._index.get(id(judged))
        if i is None:
            i = self._index[id(judged)] = len(observed.distinct)
            observed.distinct.append(judged)  # type: ignore[arg-type]
            observed.counts.append(1)
        else:
            observed.counts[i] += 1
        observed.observe(i, None)

    def __len__(self) -> int:
        return len(self.observed)

    def alike(self) -> Alike:
        """The observations as :func:`combine` reads them (one by one where iterated)."""
        return Alike(self.observed)


def _distribution_of_one_window(
    window: Window, distinct: list[Measured], counts: list[int], count: int
) -> Distribution:
    """:func:`distribution` of ``count`` observations, ``distinct`` each ``counts`` times,
    judged against ``window``: the same figures as one by one. Equal values have equal
    slacks against one window, so which of them a sorted position picks does not matter;
    the position ``p`` of the values sorted is found among the distinct ones by the running
    counts (:func:`_sorted_positions`)."""
    lo, hi = window.lo, window.hi
    values, at = _sorted_positions([m.measured for m in distinct], counts)
    ticks = [at(p) for p in _tick_positions(count)]
    mid = _median_of_positions(at, count)
    u_mid = _median_of_positions(
        _sorted_positions([m.uncertainty for m in distinct], counts)[1], count
    )
    return Distribution(
        count,
        _ms(values[0]) or 0.0,
        _ms(mid) or 0.0,
        _ms(values[-1]) or 0.0,
        _ms(lo),
        _ms(hi),
        _ms(u_mid) or 0.0,  # the median of the uncertainties, as statistics.median gives it
        _ms(min(_slack(lo, hi, m) for m in values)) or 0.0,
        mixed_limits=False,
        values_ms=[_ms(v) or 0.0 for v in ticks],
        slack_ms=[_ms(_slack(lo, hi, v)) or 0.0 for v in ticks],
    )


def _tick_positions(count: int) -> Iterable[int]:
    """The sorted positions a distribution of ``count`` values shows: every one, or
    :data:`MAX_TICKS` evenly through them (min and max kept)."""
    if count > MAX_TICKS:
        step = (count - 1) / (MAX_TICKS - 1)
        return [round(i * step) for i in range(MAX_TICKS)]
    return range(count)


def _sorted_positions(
    distinct: list[float], counts: list[int]
) -> tuple[list[float], Callable[[int], float]]:
    """``distinct`` sorted, and the value at a position of the list where each comes
    ``counts`` times (found by the running counts, not by making that list)."""
    order = sorted(range(len(distinct)), key=distinct.__getitem__)
    values = [distinct[i] for i in order]
    ends = list(accumulate(counts[i] for i in order))  # sorted position after each value
    return values, lambda p: values[bisect_right(ends, p)]


def _median_of_positions(at: Callable[[int], float], count: int) -> float:
    """``statistics.median`` of ``count`` sorted values, each at ``at(position)``."""
    middle = count // 2
    return at(middle) if count % 2 else (at(middle - 1) + at(middle)) / 2


def _window_verdict(
    lo: float | None, hi: float | None, measured: float, uncertainty: float, should: bool
) -> tuple[Verdict, bool]:
    """The verdict of ``measured ± uncertainty`` against ``[lo, hi]``, and whether the whole
    interval lies outside."""
    m_lo, m_hi = measured - uncertainty, measured + uncertainty
    inside = (lo is None or m_lo >= lo) and (hi is None or m_hi <= hi)
    outside = (lo is not None and m_hi < lo) or (hi is not None and m_lo > hi)
    if inside:
        return _PASS, outside
    if outside:
        return (_WARN if should else _FAIL), outside
    return _INCONCLUSIVE, outside


def _margin_ms(lo: float | None, hi: float | None, measured: float, outside: bool) -> float | None:
    """How far (ms) ``measured`` sits from the edge that decided it: the nearer edge, or,
    outside the window, the edge it is beyond."""
    nearest = None
    for edge in (None if lo is None else measured - lo, None if hi is None else hi - measured):
        if edge is None or (outside and edge >= 0):
            continue
        distance = -edge if outside else abs(edge)
        if nearest is None or distance < nearest:
            nearest = distance
    return None if nearest is None else round(nearest * 1e3, 3)


def _margin_inside_ms(lo: float | None, hi: float | None, measured: float) -> float | None:
    """``_margin_ms(lo, hi, measured, False)`` without its loop over a tuple of edges: asked
    for every interval a run judges surely inside (a run's ~900 reply starts twice and its
    distinct character gaps, issue 22, matrix23); the nearer edge, the first on a tie."""
    if lo is None:
        return None if hi is None else round(abs(hi - measured) * 1e3, 3)
    if hi is None:
        return round(abs(measured - lo) * 1e3, 3)
    return round(min(abs(measured - lo), abs(hi - measured)) * 1e3, 3)


class Measured:
    """One interval judged against a :class:`Window`, standing in for its :class:`Finding`
    among the observations :func:`combine` and :func:`combine_local` aggregate: they read
    every observation's verdict and figures but the detail text and evidence of only the few
    a verdict shows (the worst, a lone deviation), so only those are built; a run judges tens
    of thousands of character gaps. A FAIL or WARN is built at once: the finding's own rules
    (:class:`Finding`: evidence, the rule's level) may change its verdict."""

    __slots__ = ("_finding", "_window", "margin_ms", "measured", "measured_ms", "uncertainty",
                 "verdict", "evidence_lines")  # fmt: skip

    observed = 1  # one measured interval between two observed wire events

    def __init__(
        self,
        window: Window,
        measured: float,
        uncertainty: float,
        evidence: list[str] | Callable[[], list[str]] | None,
    ) -> None:
        lo, hi = window.lo, window.hi
        self._window = window
        self.measured = measured
        self.uncertainty = uncertainty
        self.evidence_lines = evidence
        self._finding: Finding | None = None
        self.measured_ms = round(measured * 1e3, 3)
        if (lo is None or measured - uncertainty >= lo) and (
            hi is None or measured + uncertainty <= hi
        ):  # surely inside, as nearly every one is: _window_verdict's PASS, without the call
            self.verdict = _PASS
            self.margin_ms = _margin_inside_ms(lo, hi, measured)
            return
        verdict, outside = _window_verdict(lo, hi, measured, uncertainty, window.should)
        if verdict is _FAIL or verdict is _WARN:
            self._finding = window.judge(measured, uncertainty, self._evidence())
            verdict = self._finding.verdict
        self.verdict = verdict
        self.margin_ms = _margin_ms(lo, hi, measured, outside)

    @property
    def finding(self) -> Finding:
        """The finding :func:`judge_window` gives for this interval."""
        if self._finding is None:
            self._finding = self._window.judge(self.measured, self.uncertainty, self._evidence())
        return self._finding

    def _evidence(self) -> list[str] | None:
        """The evidence lines its finding gets: the list given, or what the callable given
        makes, asked only when the finding is built (a reply's start is measured for every
        reply of a run, its line read for the few a verdict shows: ``judges/wire``);
        :class:`MeasuredIn` makes its own when asked."""
        lines = self.evidence_lines
        return lines() if callable(lines) else lines

    @property
    def requirement(self) -> str:
        return self._window.requirement

    @property
    def detail(self) -> str:
        return self.finding.detail

    @property
    def evidence(self) -> list[str]:
        # a copy: what combine() hands on may be extended by its reader, and the observations
        # may be shared by several judges of one run
        return list(self.finding.evidence)

    @property
    def limit_ms(self) -> float | None:
        return self.finding.limit_ms

    @property
    def uncertainty_ms(self) -> float | None:
        return round(self.uncertainty * 1e3, 3)

    @property
    def decision(self) -> str | None:
        return self._window.decision


class MeasuredAsJudged(Measured):
    """A :class:`Measured` that aggregates exactly as its :func:`judge_window` finding did:
    :func:`distribution` reads its figures rounded to the ms the finding's own distribution
    holds (a plain :class:`Measured` gives the seconds), made when asked and not kept. A
    judge that kept a whole :class:`Finding` per interval (the recorder's command character
    gaps: an hour of a busy bus's 45,000, some 1.3 kB each) holds this instead, with the
    same verdict, detail and figures (``tests/judges/test_timing_measured_as_judged.py``)."""

    __slots__ = ()

    @property
    def distribution(self) -> Distribution:
        window = self._window
        return _single(self.measured, self.uncertainty, window.lo, window.hi)


_M = TypeVar("_M", bound=Measured)


class Repeats(Generic[_M]):
    """The intervals of one window judged so far, by value: an interval equal to one judged
    before (the same measurement, the same uncertainty, the same sign of a zero) is that
    first one again. :func:`combine` and :func:`distribution` read an object that comes
    again as they read the equal objects it stands for (the first of the worst is the one
    shown, its evidence the first interval's), so a judge of many intervals holds one object
    per distinct value, not one per interval (an hour of a busy bus: 180,000 command
    character gaps and 15,000 breaks, a few hundred values)."""

    def __init__(self) -> None:
        self._seen: dict[tuple[float, float], _M] = {}

    def first(self, measured: float, uncertainty: float) -> _M | None:
        """The first interval judged equal to this one (None: the first of its value)."""
        seen = self._seen.get((measured, uncertainty))
        if seen is None or copysign(1.0, measured) != copysign(1.0, seen.measured):
            return None
        if measured != measured or uncertainty != uncertainty:
            return None  # a NaN is never another interval's value, even the one object
        return seen

    def keep(self, judged: _M) -> _M:
        """``judged``, kept as the first of its value (unless a zero of the other sign is)."""
        self._seen.setdefault((judged.measured, judged.uncertainty), judged)
        return judged


class _Located(Protocol):
    def at(self) -> str: ...


class MeasuredIn(MeasuredAsJudged):
    """A :class:`MeasuredAsJudged` whose evidence is ``in <where.at()>``, the line made only
    when its finding is (a FAIL or WARN at once, else when a verdict shows it): it holds the
    transmission it was measured in, which the view holds anyway, where a list and a string
    per interval were made for the few ever read (an hour of a busy bus: 180,000 command
    character gaps, R-7.0-13)."""

    __slots__ = ()

    def __init__(self, window: Window, measured: float, uncertainty: float, where: _Located):
        super().__init__(window, measured, uncertainty, where)  # type: ignore[arg-type]

    def _evidence(self) -> list[str]:
        return [f"in {self.evidence_lines.at()}"]  # type: ignore[attr-defined]


def recheck(findings: list[Finding], uncertainty: float) -> int:
    """Judge timing findings again against the run's final measured ``uncertainty`` (s):
    a PASS, WARN or FAIL whose margin the larger figure no longer clears becomes
    INCONCLUSIVE (a verdict must hold for every stamp error the run has shown possible).
    Returns how many changed."""
    changed = 0
    u_ms = uncertainty * 1e3
    for f in findings:
        if f.margin_ms is None or f.uncertainty_ms is None or u_ms <= f.uncertainty_ms:
            continue
        if f.verdict not in (_PASS, _WARN, _FAIL) or f.margin_ms > u_ms:
            continue
        f.detail += (
            f" — but the link's measured uncertainty grew to ±{u_ms:.2f} ms later in the run, "
            f"more than this {f.margin_ms:.2f} ms margin: not decided"
        )
        f.verdict = _INCONCLUSIVE
        f.uncertainty_ms = round(u_ms, 3)
        changed += 1
    return changed


def undecide_after_late_line(findings: list[Finding], late: float, allowed: float) -> int:
    """A line this tool served in real time fell ``late`` s behind its schedule (more than
    ``allowed``): the played sensors answered later than planned, and what the recorder did
    next (a retry, a timeout, a reading order) may be its right reaction to that, not a
    deviation of its own. Every FAIL and WARN becomes INCONCLUSIVE, saying so. Returns how
    many changed."""
    changed = 0
    for f in findings:
        if f.verdict not in (_FAIL, _WARN):
            continue
        f.detail += (
            f" — but the served line fell {late * 1e3:.1f} ms behind its schedule in this run "
            f"(more than {allowed * 1e3:.0f} ms: the host was too busy), so the played sensors "
            "may have answered late and the recorder may have reacted to that: not decided"
        )
        f.verdict = _INCONCLUSIVE
        changed += 1
    return changed


def _describe_limit(lo: float | None, hi: float | None) -> str:
    if lo is not None and hi is not None:
        return f"{lo * 1e3:.2f}..{hi * 1e3:.2f} ms"
    if hi is not None:
        return f"≤ {hi * 1e3:.2f} ms"
    if lo is not None:
        return f"≥ {lo * 1e3:.2f} ms"
    return "any"


#: Words that end the head noun of a phrase such as "retry after no reply".
_PREPOSITIONS = frozenset(
    [
        "after",
        "before",
        "between",
        "for",
        "from",
        "in",
        "inside",
        "of",
        "on",
        "to",
        "with",
        "without",
    ]
)


def plural(what: str) -> str:
    """The plural of a counted phrase: its head noun, the word before the first preposition
    ("retries after no reply", "commands without a break"); a command (``aD0!``) stays."""
    words = what.split(" ")
    head = next((i - 1 for i, w in enumerate(words) if i and w in _PREPOSITIONS), len(words) - 1)
    noun = words[head]
    if noun.endswith("!"):
        return what
    if noun.endswith("y") and not noun.endswith(("ay", "ey", "oy")):
        words[head] = noun[:-1] + "ies"
    else:
        words[head] = noun + ("es" if noun.endswith(("s", "sh", "ch", "x")) else "s")
    return " ".join(words)


def counted(n: int, what: str) -> str:
    """``1 retry after no reply``, ``6 retries after no reply``."""
    return f"{n} {what if n == 1 else plural(what)}"


def combine(
    rid: str, findings: Sequence[Finding | Measured], what: str, *, smallest_is_worst: bool = False
) -> Finding:
    """One finding per requirement out of many observations: the worst verdict (and, among
    equals, the largest measurement, or the smallest for minimum limits such as a break's
    length), with the range of all of them, so a reader sees one line per rule."""
    if not findings:
        return Finding(rid, _INCONCLUSIVE, f"no {what} was observed")
    sign = -1 if smallest_is_worst else 1
    # each object once, in the order it first comes (a run's character gaps: tens of
    # thousands, a few hundred distinct): the first of the largest is the same either way
    if type(findings) is Alike:
        distinct: list[Finding | Measured] = list(findings.distinct)
        observed = sum(f.observed * c for f, c in zip(distinct, findings.counts, strict=True))
    else:
        distinct = list({id(f): f for f in findings}.values())
        observed = sum(f.observed for f in findings)
    # the first with the worst verdict and, among those, the largest (smallest) measurement
    top = max({f.verdict for f in distinct}, key=lambda v: v.rank)
    worst = max(
        (f for f in distinct if f.verdict is top), key=lambda f: sign * abs(f.measured_ms or 0)
    )
    values = [f.measured_ms for f in distinct if f.measured_ms is not None]
    count = counted(len(findings), what)
    span = f"{count}, {min(values):.2f}..{max(values):.2f} ms" if values else ""
    if worst.verdict is _PASS and ", allowed " in worst.detail:
        detail = f"{span}; all inside the limit ({worst.detail.split(', allowed ')[-1]})"
    elif worst.verdict is _PASS:
        detail = f"{count} observed; {span + '; ' if span else ''}{worst.detail}"
    else:
        parts = [worst.detail]
        if worst.evidence and worst.evidence[0] not in worst.detail:
            parts[0] += f" [{worst.evidence[0]}]"  # where, when the detail does not say it
        if span:
            parts.append(span)
        detail = "; ".join(parts)
    same = [f.margin_ms for f in distinct if f.verdict is worst.verdict]
    margins = [m for m in same if m is not None]
    margin = None
    if margins and len(margins) == len(same):
        # every PASS must hold; for a FAIL, one that holds is enough
        margin = max(margins) if worst.verdict in (_FAIL, _WARN) else min(margins)
    return Finding(
        rid,
        worst.verdict,
        detail,
        measured_ms=worst.measured_ms,
        limit_ms=worst.limit_ms,
        uncertainty_ms=worst.uncertainty_ms,
        evidence=worst.evidence,
        margin_ms=margin,
        observed=observed,
        distribution=distribution(findings),
    )
