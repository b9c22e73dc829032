"""Whether a sensor was awake to hear a try: silence is evidence only from a sensor shown to
be listening at that moment.

A compliant sensor may need up to 100 ms after a break before it catches a start bit
(R-7.0-07), which is why a recorder's retry sequence puts one retry more than 100 ms after
its break (R-7.2-03). A try sent 9 ms after a break of its own is heard by a sensor quick to
wake and may be missed by one that takes its full 100 ms. When every try of an exchange went
that soon after a break (a loaded host came back more than 87 ms after each try, so the break
rule put a break in front of each retry), the sensor's silence says nothing of the command:
slow-wake behind an echoing RFC 2217 link with 2 ms of jitter and two CPU burners FAILed
R-6.2-05 "0IM_000! got no reply", 9 tries each 9-20 ms after a break of its own (truth23).

What a run shows beyond the 100 ms: an exchange answered only by a later try of a sequence
whose earlier tries, each after the same break, went unanswered, shows that the sensor needs
more than those tries' marking after a break (:func:`wake_shown`).
"""

from __future__ import annotations

from ..protocol.timing import TOLERANCE, WAKE_LIMIT
from ..tool_recorder.records import CONTENTION, Attempt, Exchange
from ..transcript import Event, escape

#: marking after a break (s) under which a compliant sensor may still be waking (R-7.0-07)
WAKE_NEED = WAKE_LIMIT + TOLERANCE


def markings(ex: Exchange, brk: Event | None = None) -> list[tuple[Attempt, float | None, float]]:
    """Each try of ``ex`` with the marking (s) between the end of the latest break before it
    (its own, an earlier try's, else ``brk``) and its first start bit, and that figure's
    uncertainty (the larger of the two stamps'). None for a try with no break before it
    that the exchange (or ``brk``) shows: the sensor may have been awake from what went
    before, which this exchange does not hold."""
    latest = brk
    out: list[tuple[Attempt, float | None, float]] = []
    for a in ex.attempts:
        if a.break_event is not None:
            latest = a.break_event
        if not a.command_events:
            continue
        first = a.command_events[0]
        if latest is None:
            out.append((a, None, first.uncertainty))
            continue
        out.append((a, first.start - latest.end, max(latest.uncertainty, first.uncertainty)))
    return out


def wake_shown(ex: Exchange, brk: Event | None = None) -> float:
    """The marking after a break (s) under which ``ex`` shows the sensor may not hear: the
    100 ms (+0.4) any sensor may need, or more where a sequence of ``ex`` was answered only
    by a later try after earlier ones, each after the same break, went unanswered (the
    longest of those tries' markings with its uncertainty: the sensor needed more)."""
    need = WAKE_NEED
    tries = markings(ex, brk)
    for i, (a, _, _) in enumerate(tries):
        if not a.reply_events or a.break_event is not None:
            continue  # unanswered, or answered after a break of its own: no wake-up shown
        for b, marking, u in reversed(tries[:i]):
            if b.sequence != a.sequence or b.reply_events or b.stray_events or marking is None:
                break
            need = max(need, marking + u)
            if b.break_event is not None:
                break  # the break ``a`` and these tries followed
    return need


def unheard(ex: Exchange, brk: Event | None = None) -> str:
    """Why the silence of ``ex`` is no evidence ('' when it is): unanswered, sent with
    retries, and every try began less than :func:`wake_shown` after the break before it (the
    upper end of its uncertainty included), so none went when the sensor must have been awake
    to hear it. A try with no break before it in ``ex`` (nor ``brk``) went while the
    sensor was awake from before, as the engine's break rule judged: evidence. A try the
    sensor's characters met (bus contention) is neither silence nor an answer: set aside, as
    the engine sets it aside (slow-wake behind the jittery link: the tool's own 0IMC3! came
    back stalled 58 ms inside, the sensor's '00000' met its echo, the four retries each
    went 11-16 ms after a break of their own, and R-6.1-01 FAILed "no reply", truth23)."""
    if ex.answered or len(ex.attempts) < 2 or any(a.reply_events for a in ex.attempts):
        return ""
    tries = markings(ex, brk)
    quiet = [(a, m, u) for a, m, u in tries if not a.reason.startswith(CONTENTION)]
    if not quiet:
        return ""
    need = wake_shown(ex, brk)
    if any(m is None or m - u >= need for _, m, u in quiet):
        return ""
    known = [m for _, m, _ in quiet if m is not None]
    lo, hi = min(known) * 1e3, max(known) * 1e3
    met = len(tries) - len(quiet)
    aside = f" ({met} more met by the sensor's characters)" if met else ""
    return (
        f"{escape(ex.text)}: none of its {len(quiet)} tries{aside} went when the sensor must"
        f" have been awake: each began {lo:.2f}-{hi:.2f} ms after the break before it, under"
        f" the {need * 1e3:.1f} ms a sensor may need to wake (R-7.0-07 judges that), so its "
        "silence shows nothing"
    )


def first_sequence_unheard(ex: Exchange, brk: Event) -> str:
    """Why silence to the first sequence of ``ex``, sent right after ``brk`` (an aborting
    break), is no evidence that the sensor ignored it ('' when it is): none of that
    sequence's tries without a break of their own was answered, and each began less than
    :func:`wake_shown` after ``brk``. slow-wake behind the jittery echoing link: 0M! 11 ms
    and 107 ms after the aborting break went unheard, the next retry came too late to go
    without a break, and R-4.4.5.1-03 FAILed "ignored the M sent right after the aborting
    break", while the same exchange's third sequence showed the sensor needed more than
    109 ms after a break (truth23)."""
    if any(a.reply_events for a in ex.attempts if a.sequence == 0):
        return ""  # heard in that sequence, after a break of its own or not
    tries = [t for t in markings(ex, brk) if t[0].sequence == 0 and t[0].break_event is None]
    if not tries:
        return ""
    need = wake_shown(ex, brk)
    if any(m is None or m - u >= need for _, m, u in tries):
        return ""
    shown = ", ".join(f"{m * 1e3:.2f}" for _, m, _ in tries if m is not None)
    return (
        f"{escape(ex.text)}'s tries without a break of their own began {shown} ms after the "
        f"aborting break, under the {need * 1e3:.1f} ms this sensor was shown to need to wake"
        " (R-7.0-07 judges that), so their silence shows nothing of the abort"
    )


def woken_unheard(tries: list[Exchange], brk: Event, uncertainty: float) -> str:
    """Why silence to ``tries`` (single transmissions after ``brk``, none behind a break of
    its own) does not show that ``brk`` failed to wake the sensor ('' when it does): none
    began surely more than 100.4 ms after the break (a woken sensor may need that long,
    R-7.0-07) and surely less than 100 ms (-0.4) after the line's previous activity (the
    try before, where a woken sensor is back in standby, R-7.0-15). slow-wake behind the
    jittery echoing link: the case's retries, meant 40 and 60 ms after the try before, went
    225 and 253 ms after it on the loaded host, and R-7.0-04 FAILed "no reply to a! or 2
    retries after a 12.61 ms break" (truth23)."""
    before = brk.end
    seen = []
    for ex in tries:
        first = ex.attempts[0].command_events if ex.attempts else []
        if not first:
            return ""
        start = first[0].start
        woke, idle = start - brk.end, start - before
        seen.append(f"{woke * 1e3:.2f} ms after the break, {idle * 1e3:.2f} ms after the last")
        if woke - uncertainty >= WAKE_NEED and idle + uncertainty < WAKE_LIMIT - TOLERANCE:
            return ""
        before = first[-1].end
    return (
        "no try went while a sensor woken by the break must have been listening (over 100.4 "
        "ms after it, under 99.6 ms after the line's last activity): " + "; ".join(seen)
    )
