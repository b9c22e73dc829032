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
    it did transmit, which is the observation the absence rests on."""
    wanted = set(texts or [])
    cited = [t.at() for t in transmissions if t.text in wanted]
    if cited:
        return cited[:8]
    if not transmissions:
        return ["the recorder transmitted nothing"]
    first, last = transmissions[0], transmissions[-1]
    sent = sorted({escape(t.text) for t in transmissions})
    return [
        f"{len(transmissions)} transmissions from t={first.first_char:.3f} s to "
        f"t={last.first_char:.3f} s, of {len(sent)} kinds: "
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
