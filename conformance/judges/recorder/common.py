"""What the recorder judges share: how findings over many observations combine, and the
tool's decisions on how long a recorder may take."""

from __future__ import annotations

from ...protocol.commands import SERVICE_REQUEST_KINDS, Kind
from ...verdicts import Finding
from ..timing import combine as combine_timing

#: A recorder reacts to a service request (or to ttt running out) with aD0! within this long.
#: The standard says "when it arrives"; the tool allows half a second for a logger's own work
#: and fails only a recorder that visibly waits for something else (a tool decision).
REACTION = 0.5
#: Values a recorder must be able to store from one concurrent measurement (R-4.4.7-07, 2000).
MIN_CONCURRENT_STORE = 20
#: Measurements that end their wait with a service request (M family, V).
SR_KINDS = SERVICE_REQUEST_KINDS
CONCURRENT_KINDS = (Kind.CONCURRENT, Kind.HIGH_VOLUME_ASCII, Kind.HIGH_VOLUME_BINARY)


def combine(rid: str, findings: list[Finding], what: str) -> Finding:
    """Recorder limits are mostly minimums (break length, marking, waits): the smallest
    measurement is the one to show."""
    return combine_timing(rid, findings, what, smallest_is_worst=True)
