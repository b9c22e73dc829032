"""Judging a record whose read the tool's own host stalled over (truth26, truth27).

When the tool's process is held up (a loaded host, a paused process), the reply being read
may be cut and its rest delivered in a late burst that is taken for later text, a retry's
reply or nothing: what such a read shows is the host's doing, not the DUT's. The link notes
each stall in the transcript (:mod:`~conformance.links.host_stall`), and every attempt whose
read one may have held up carries it (:attr:`~conformance.tool_recorder.records.Attempt.
stall`, :attr:`~conformance.tool_recorder.records.Exchange.stall` of the attempt judged).
Here is how a judge reads such a record: a violation it shows is INCONCLUSIVE with the stall
named, never FAIL or WARN; what conforms is judged as ever, and a record outside any stall
exactly as before.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from ..links.host_stall import Stall
from ..protocol.values import Violation
from ..tool_recorder.records import Exchange
from ..verdicts import Finding, Verdict
from .tally import Tally
from .timing import Measured

_DEVIATING = (Verdict.FAIL, Verdict.WARN)
_EITHER_WAY = (Verdict.FAIL, Verdict.WARN, Verdict.PASS)


class StalledTally(Tally):
    """``tally`` seen through a stall of the tool's own host over the read of the record
    observed (``why``: :meth:`~conformance.links.host_stall.Stall.why`): a violation (FAIL
    or WARN) leaves its rule undecided with the stall named, since the read may have been
    cut and its rest taken for something else (truth26, truth27: a clean emulator FAILed
    "lacks the CRC", value counts and framing under 80-200 ms pauses); what conforms is
    observed as ever. It is the same tally (its counts, violations and undecided lists are
    ``tally``'s own), so an undecided observation keeps another's PASS from standing for
    it and a violation found elsewhere still FAILs the rule."""

    def __init__(self, tally: Tally, why: str) -> None:  # shares tally's state: no super()
        self.__dict__.update(tally.__dict__)  # the very dicts: one tally, two doors
        self.why = why

    def observe(
        self, where: str, violations: Iterable[Violation] = (), ids: Iterable[str] | None = None
    ) -> None:
        kept = []
        for v in violations:
            if v.requirement in self.violations:
                self.undecide(v.requirement, where, f"{v.message}, but {self.why}")
            else:
                kept.append(v)
        super().observe(where, kept, ids)


def through_stall(tally: Tally, stall: Stall | None) -> Tally:
    """``tally``, or where ``stall`` (a record's :attr:`~conformance.tool_recorder.records.
    Exchange.stall`) held up the read observed, :class:`StalledTally` of it."""
    return tally if stall is None else StalledTally(tally, stall.why())


def unless_stalled(
    finding: Finding, exchanges: Iterable[Exchange], *, together: bool = False
) -> Finding:
    """``finding``, or where it FAILs or WARNs and the reads of ``exchanges`` (those showing
    what it found) were all stalled, the same INCONCLUSIVE with the (first) stall named: for
    a judge that gives a finding of its own rather than a tally's. One read outside any
    stall that shows it, and the finding stands. ``together``: what it found rests on the
    reads together (values counted over several replies), so one stalled read undecides it."""
    if finding.verdict not in (Verdict.FAIL, Verdict.WARN):
        return finding
    stalls = [ex.stall for ex in exchanges]
    held = [stall for stall in stalls if stall is not None]
    if not held or (len(held) < len(stalls) and not together):
        return finding
    return held_by(finding, held[0])


def held_by(finding: Finding, stall: Stall | None, *, either_way: bool = False) -> Finding:
    """``finding``, or where it FAILs or WARNs on what ``stall`` (a stall of the tool's own
    host over the stamps or the read it rests on) may have moved or cut, the same
    INCONCLUSIVE with the stall named: a finding that rests on one such record (a
    measurement's wait, :attr:`~conformance.tool_recorder.records.Measurement.wait_stall`).
    ``either_way``: a PASS too, for a finding on silence (truth30: a standby probe the stall
    moved past the 100 ms, or whose answer it cut, is silent for the host's reasons; the
    product's rule is that silence is evidence only from a sensor shown listening then)."""
    held = _EITHER_WAY if either_way else _DEVIATING
    if stall is None or finding.verdict not in held:
        return finding
    detail = f"{finding.detail}, but {stall.why()}"
    return replace(finding, verdict=Verdict.INCONCLUSIVE, detail=detail)


def stalled_interval(measured: Finding | Measured, stall: Stall) -> Finding:
    """A deviating interval whose stamps ``stall`` may have moved (truth29: a character the
    tool's host held back is stamped at the late burst that delivers it, a reply start late,
    a gap long; a FAIL or WARN, as :func:`held_by` takes): INCONCLUSIVE with the stall
    named. The whole-run timing judges set it
    aside as they set aside an interval the link's irregular stamps leave undecided
    (:func:`~.timing.combine_local`, which names the stall and asks for that place to be
    observed again, :func:`~.timing.to_confirm`)."""
    return held_by(measured.finding if isinstance(measured, Measured) else measured, stall)
