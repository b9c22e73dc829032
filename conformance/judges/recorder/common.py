"""What the recorder judges share: how findings over many observations combine, and the
tool's decisions on how long a recorder may take."""

from __future__ import annotations

from collections.abc import Sequence

from ...protocol.commands import SERVICE_REQUEST_KINDS
from ...transcript import Event, escape
from ...verdicts import Finding
from ...view.segments import Transmission
from ..timing import Measured
from ..timing import combine as combine_timing

#: A recorder reacts to a service request (or to ttt running out) with aD0! within this long.
#: The standard gives no figure (and lets a recorder wait the whole ttt), so this is the tool's
#: allowance for a logger's own work, catalog decision T1: a later aD0! is a WARN citing it,
#: never a FAIL on its own.
REACTION = 0.5
REACTION_DECISION = "T1"


def beyond_reaction(delay: float, what: str) -> str:
    """The words of a WARN for an aD0! ``delay`` s after ``what``: the figure and whose it is."""
    return (
        f"aD0! came {delay:.3f} s after {what}, later than the {REACTION} s the tool allows "
        f"(decision {REACTION_DECISION}: the standard gives no figure, so not a FAIL)"
    )


#: Why an absence proves nothing in a view with a job the tool cut at its budget
#: (``TranscriptView.cut_parts``): the recorder was still in that job, and what it had not
#: sent by then it may still have sent. Such an absence is undecided, never a FAIL.
CUT_SHORT = "not sent before the tool cut a job at its budget"

#: Values a recorder must be able to store from one concurrent measurement (R-4.4.7-07, 2000).
MIN_CONCURRENT_STORE = 20
#: Measurements that end their wait with a service request (M family, V).
SR_KINDS = SERVICE_REQUEST_KINDS


def record_of(transmissions: list[Transmission], texts: list[str] | None = None) -> list[str]:
    """Evidence for a finding about what the recorder did not do (issue 18): the transmissions
    of ``texts`` it made (each with its time), or, if it made none of them, the span of what
    it did transmit, which is the observation the absence rests on (one
    :meth:`Record.add`: the windowed judges' code path)."""
    record = Record(texts or [])
    record.add(transmissions)
    return record.evidence(texts or [])


class Record:
    """:func:`record_of` of a recording given a window's transmissions at a time (issue 22's
    windowed judge), for any of the ``candidates`` texts, the finding choosing which at the
    end (R-4.3-03 cites the polls of the addresses no valid reply answered, known only
    then): carried, each candidate's first :data:`CITED` transmissions (with their place in
    the recording), the count of transmissions, the first and the last one's time and the
    distinct texts sent, not the transmissions."""

    CITED = 8

    def __init__(self, candidates: Sequence[str]) -> None:
        self._cited: dict[str, list[tuple[int, str]]] = {t: [] for t in candidates}
        self.count = 0  # transmissions so far
        self._first: float | None = None
        self._last: float | None = None
        self._sent: set[str] = set()

    def add(self, transmissions: Sequence[Transmission]) -> None:
        """Take the next window's transmissions."""
        for i, t in enumerate(transmissions, self.count):
            cited = self._cited.get(t.text)
            if cited is not None and len(cited) < self.CITED:
                cited.append((i, t.at()))
            self._sent.add(t.text)
        if transmissions:
            if self._first is None:
                self._first = transmissions[0].first_char
            self._last = transmissions[-1].first_char
        self.count += len(transmissions)

    def evidence(self, texts: Sequence[str]) -> list[str]:
        """The evidence for ``texts`` (candidates given at the start)."""
        cited = sorted(c for t in set(texts) for c in self._cited[t])
        if cited:
            return [at for _, at in cited[: self.CITED]]
        if not self.count:
            return ["the recorder transmitted nothing"]
        sent = sorted({escape(t) for t in self._sent})
        return [
            f"{self.count} transmissions from t={self._first:.3f} s to "
            f"t={self._last:.3f} s, of {len(sent)} kinds: "
            + " ".join(sent[:20])
            + (" ..." if len(sent) > 20 else "")
        ]


def own_uncertainty(uncertainty: float, *events: Event) -> float:
    """The uncertainty (s) of an interval between ``events``: the run's figure, or wider
    where an event's own stamp is (a served line's characters read together with others may
    have been sent anywhere in the span before that read: their gaps and places are not
    known to the run's figure, and a verdict must not rest on them)."""
    u = uncertainty
    for e in events:
        if e.uncertainty > u:
            u = e.uncertainty
    return u


def combine(rid: str, findings: Sequence[Finding | Measured], what: str) -> Finding:
    """Recorder limits are mostly minimums (break length, marking, waits): the smallest
    measurement is the one to show."""
    return combine_timing(rid, findings, what, smallest_is_worst=True)
