"""The wait rules (a service request's form, timing and what comes before it; the quiet of a
concurrent measurement) over the measurements the run made outside the cases that own them.

The cases that own R-4.4.6-04 and its kin judge the session's cached measurements (one of
each command). A case that measures again (the data-retention case, the metadata case's
fresh aM!, a CRC case...) waits for a service request too, and a late or malformed one there
is the sensor's as much: judged nowhere, it let R-4.4.6-04 PASS for a sensor whose late
request was on the wire (bench31: the uOS++ sensor behind the USB model). The same judge
reads those waits, each observation under the same preconditions (an ``atttn`` reply heard,
no stall of the tool's host over the wait: :func:`~conformance.judges.stalled.through_stall`,
a SHOULD rule a WARN), and adds what it finds beside the owners' findings:

- a FAIL or WARN stands (a deviation seen on the wire);
- a PASS is ``partial``: it speaks for these measurements, not for the rule, so where no
  owner judged the rule it does not make it PASS (:func:`~conformance.results.partial_only`);
- an observation these waits could not decide rests on no decisive observation of the
  rule: INCONCLUSIVE with ``observed`` 0, which the owners' judgment outweighs
  (:func:`~conformance.results.counted`) and which stands where none judged;
- nothing to judge (no such measurement): N/A, which changes no owner's verdict.

The data rules (:data:`DATA_IDS`) are weighed the same way over the same measurements
(truth35): the cases that own them judge the cached measurements' D replies alone, so a
sensor whose data went wrong only when measured again (one value fewer than announced the
second time) PASSed them. Each D reply keeps the data judge's preconditions
(:func:`~conformance.judges.measurements.data_violations`): a reply heard to a D command
of that measurement's collection; one that may be another's (a late reply, the D before's,
a service request begun too soon) is undecided; a stall of the host over its read too.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from ..tool_recorder.records import Measurement
from ..verdicts import Finding, Verdict, inconclusive, not_applicable
from .measurements import judge, unread_data

#: The rules a measurement's wait is judged on (:func:`~conformance.judges.measurements.
#: wait_violations`), less R-5.3-01 (a high-volume measurement's, whose case needs breaks):
#: an M-type measurement's service request, as ``test_service_request`` judges it ...
SERVICE_REQUEST_IDS = ("R-4.4.6-01", "R-4.4.6-02", "R-4.4.6-04", "R-4.4.5-08", "R-4.4.5-09")
#: ... and the quiet of a concurrent one, as the concurrent cases judge it
QUIET_IDS = ("R-4.4.6-05", "R-4.4.7-04")
WAIT_IDS = SERVICE_REQUEST_IDS + QUIET_IDS
#: The rules over an ASCII measurement's D replies, as the data and CRC cases judge the
#: cached ones (``test_data_replies``, ``test_announced_values_delivered``,
#: ``test_value_grouping``, ``test_crc_presence``, ``test_crc_value_and_encoding``): their
#: form and values (R-4.4.8-01, -02), the values part's length (R-4.4-05), the count adding
#: up (R-4.4.8-03), a D0 with values (R-4.4.8-04), the grouping (R-4.4.8.3-01..03), the
#: CRC where asked for and not elsewhere (R-4.4.12-02, -03), its value and encoding
#: (R-4.4.12-05, -06)
DATA_IDS = (
    "R-4.4.8-01",
    "R-4.4.8-02",
    "R-4.4-05",
    "R-4.4.8-03",
    "R-4.4.8-04",
    "R-4.4.8.3-01",
    "R-4.4.8.3-02",
    "R-4.4.8.3-03",
    "R-4.4.12-02",
    "R-4.4.12-03",
    "R-4.4.12-05",
    "R-4.4.12-06",
)

WHAT = "the measurements other cases made again"


def judge_other_waits(
    measurements: Sequence[Measurement], ids: Sequence[str], version: str
) -> list[Finding]:
    """Findings for ``ids`` over ``measurements`` (made outside the owners' cache), weighed
    as the module says."""
    if not measurements:
        return [not_applicable(rid, f"{WHAT}: none was made") for rid in ids]
    return [_weighed(f) for f in judge(measurements, ids, version)]


def judge_other_data(
    measurements: Sequence[Measurement], ids: Sequence[str], version: str
) -> list[Finding]:
    """:func:`judge_other_waits` for the data rules: beside each rule's findings, where a
    start reply gave no readable count (its D replies never asked for), the rule undecided
    there (:func:`~conformance.judges.measurements.unread_data`), weighed as the rest."""
    found = judge_other_waits(measurements, ids, version)
    return found + [_weighed(f) for f in unread_data(measurements, ids)]


def _weighed(f: Finding) -> Finding:
    if f.verdict in (Verdict.FAIL, Verdict.WARN):
        return replace(f, detail=f"in {WHAT}: {f.detail}")
    if f.verdict is Verdict.PASS:
        return replace(f, detail=f"in {WHAT}: {f.detail}", partial=True)
    if f.verdict is Verdict.INCONCLUSIVE and f.observed:
        return inconclusive(
            f.requirement,
            f"undecided in {WHAT}: {f.detail}",
            decision=f.decision,
            evidence=list(f.evidence),
            observed=0,
        )
    if f.verdict is Verdict.INCONCLUSIVE:
        return not_applicable(f.requirement, f"nothing of it in {WHAT} ({f.detail})")
    return f
