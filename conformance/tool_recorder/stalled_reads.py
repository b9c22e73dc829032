"""Which of a run's records were read while the tool's own host stalled (truth27).

The link (I/O) notes its host's stalls in the transcript (:mod:`conformance.links.host_stall`);
the records built from the wire (the engine's, the view's, a recording's windows) are
marked here from those notes alone, so one decision serves every judge, live and offline.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..links.host_stall import Stall, stalled_over
from .records import Attempt, Exchange, Measurement


def read_stall(attempt: Attempt, found: list[Stall]) -> Stall | None:
    """The one decision of whether an attempt's read was stalled (truth27): the first of
    ``found`` that may have held up its listening, from its break (else its command) to
    when the listening ended (``Attempt.end``; a record rebuilt from the wire: its reply's
    end, or the first-character timeout). A reply read then may be cut, its rest a late
    burst taken for later text, a retry's reply or nothing: what it shows is the host's."""
    return stalled_over(found, attempt.start, attempt.end) if found else None


def mark_reads(exchanges: Iterable[Exchange | None], found: list[Stall]) -> None:
    """Set ``Attempt.stall`` (:func:`read_stall`) on every attempt of ``exchanges`` that has
    none yet (a None among them, another sensor's place in a rebuilt list, is passed over):
    what every judge of the records reads, live (the session's stimuli) and offline (a
    recording's windows) alike. ``found`` is first narrowed to the stalls over the span of
    the attempts (a window of a recording of a stalled run holds tens of attempts, the
    recording hundreds of stalls)."""
    if not found:
        return
    attempts = [a for ex in exchanges if ex is not None for a in ex.attempts]
    if not attempts:
        return
    first, last = min(a.start for a in attempts), max(a.end for a in attempts)
    near = [stall for stall in found if stall.overlaps(first, last)]
    if not near:
        return
    for attempt in attempts:
        if attempt.stall is None:
            attempt.stall = read_stall(attempt, near)


def wait_stall(m: Measurement, found: list[Stall]) -> Stall | None:
    """The first of ``found`` that may have cut, misdated or hidden ``m``'s service request
    (truth29): one over the wait's characters, from the first the sensor sent after the
    ``atttn`` reply (else the wait's end) to the end of the wait (its first D read's start;
    else its last character, or ttt). Characters the sensor sent during a stall are stamped
    at the late burst that delivers them: a service request split into two runs, or dated
    past ttt; one delivered after the wait ended lies in the D read's record, not the
    wait's. A stall earlier in a wait, before any character of it, moves nothing. With no
    character in it, the wait is looked at from ttt on (truth30): a stall over the engine's
    deadline leaves a request delivered in its burst queued past it, read as the D
    command's stray characters, and the record "no service request" (its NOTE is written
    as the reader resumes, before the engine's break for D0, so the D read's start alone
    missed it)."""
    if not found or m.reply_end is None or m.ttt is None:
        return None
    waited = m.waited_events
    ready = m.reply_end + m.ttt
    end = m.data[0].start if m.data else max(ready, waited[-1].end if waited else m.reply_end)
    return stalled_over(found, waited[0].start if waited else min(ready, end), end)


def mark_waits(measurements: Iterable[Measurement], found: list[Stall]) -> None:
    """Set ``Measurement.wait_stall`` (:func:`wait_stall`) on each of ``measurements``
    that has none yet, as :func:`mark_reads` marks their reads."""
    if not found:
        return
    for m in measurements:
        if m.wait_stall is None:
            m.wait_stall = wait_stall(m, found)
