"""Judges for single command/reply exchanges: a!, aI!, ?!, aAb!, silence where silence is due,
answers where an answer is due, and the continuous (R) commands.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ..case import events_of
from ..links.host_stall import Stall
from ..protocol.crc import ascii_crc
from ..protocol.responses import (
    Identification,
    check_address_reply,
    check_data_sequence,
    parse_data_reply_for,
    parse_ident,
    split_line,
)
from ..protocol.values import VALUES_MAX
from ..tool_recorder.records import Exchange
from ..transcript import decode_7e1, escape

__all__ = [
    "answered_late",
    "ascii_crc",
    "heard_late",
    "late_answer",
    "late_elsewhere",
    "late_reply",
    "late_shown",
    "cite",
    "cited",
    "escape",
    "events_of",
    "failed",
    "heard",
    "passed",
    "warned",
]
from ..preconditions import ControlledProbe, collided_answers, listening, shows_listening
from ..verdicts import Finding, Verdict, failed, inconclusive, passed, warned
from .cite import cite, cited, heard, shown
from .continued_talk import SET_ASIDE
from .late_before import (
    answered_late,
    earlier_reply,
    heard_late,
    late_answer,
    late_elsewhere,
    late_reply,
    late_shown,
    late_start_after,
)
from .measurements import shown_reply_ids, undecide_uncompared_crc
from .stalled import through_stall, unless_stalled
from .support import serves_continuous, text_instead_of_values
from .tally import Tally
from .wake_heard import unheard
from .wire import EARLY_WINDOW


def reply_only_address(ex: Exchange, expected: str, rid: str, what: str) -> Finding:
    """``a!`` and ``?!``: the reply is the address and CR LF, nothing else. One answered only
    after its windows is no silence: INCONCLUSIVE, its timing R-7.0-10's (the replies-after-
    retry sensor beside slow-wake heard only each sequence's third ?!, and its '0<CR><LF>'
    came 80 ms after the last: "?!: no reply" FAILed R-4.4.3-01, truth20)."""
    if late := late_answer(ex):
        return inconclusive(
            rid, f"{what}: {late} (R-7.0-10 judges its timing)", evidence=[cited(ex)]
        )
    if why := unheard(ex):
        return inconclusive(rid, f"{what}: {why}", evidence=[cited(ex)])
    if not ex.answered:
        no_reply = failed(rid, f"{what}: no reply", evidence=[cited(ex)], observed=1)
        return unless_stalled(no_reply, [ex])
    body, framing = split_line(ex.reply_text)
    problems = [v for v in framing if v.requirement == "R-4.2-03"]
    problems += check_address_reply(body, expected, rid)
    if problems:
        wrong = failed(
            rid,
            f"{what}: " + "; ".join(v.message for v in problems),
            evidence=[cited(ex)],
            observed=1,
        )
        return unless_stalled(wrong, [ex])
    return passed(rid, f"{what}: '{escape(ex.reply_text)}'", evidence=[shown(ex)], observed=1)


def identification(ex: Exchange, address: str) -> tuple[Identification | None, list[Finding]]:
    """R-4.4.2-01/-02 on ``aI!``. One answered only after its windows is no silence:
    INCONCLUSIVE, its timing R-7.0-10's (replies-after-retry + parity-error behind an echoing
    16 ms USB link: the late reply met the retry and was set aside as contention, and "aI! got
    no reply" FAILed both rules, outside28)."""
    ids = ("R-4.4.2-01", "R-4.4.2-02")
    if late := late_answer(ex):
        why = f"{late} (R-7.0-10 judges its timing)"
        return None, [inconclusive(rid, why, evidence=[cited(ex)]) for rid in ids]
    if why := unheard(ex):
        return None, [inconclusive(rid, why, evidence=[cited(ex)]) for rid in ids]
    if not ex.answered:
        return None, [
            unless_stalled(failed(rid, "aI! got no reply", evidence=[cited(ex)], observed=1), [ex])
            for rid in ids
        ]
    body, framing = split_line(ex.reply_text)
    ident = parse_ident(body, expected_address=address)
    tally = Tally(ids)
    through_stall(tally, ex.stall).observe(
        escape(ex.text), [v for v in ident.violations + framing if v.requirement in ids]
    )
    ok = {
        "R-4.4.2-01": f"fields: version '{ident.version}', vendor '{escape(ident.vendor)}', "
        f"model '{escape(ident.model)}', sensor version "
        f"'{escape(ident.sensor_version)}', optional '{escape(ident.optional)}'",
        "R-4.4.2-02": f"claims SDI-12 v{escape(ident.version[:1])}.{escape(ident.version[1:])}",
    }
    return ident, tally.findings(ok)


def silent(
    rid: str,
    exchanges: Iterable[Exchange],
    why: str,
    *,
    baseline: Exchange | Iterable[Exchange],
    should: bool = False,
    decision: str | None = None,
    stalled: Sequence[Stall | None] = (),
) -> Finding:
    """Each exchange must have drawn no reply (foreign address, standby, partial command).

    Silence is only evidence from a sensor that was shown to listen: ``baseline`` is the
    exchange (or exchanges) in which it answered its own address; if it answered none of
    them, a mute device would "pass", so the verdict is INCONCLUSIVE. A one-shot command
    answered after its window (:func:`heard_late`) was answered. A command that maybe
    collided (sensor characters met it within the stamps' uncertainty) may not have been
    heard, so its silence is set aside, as :func:`silent_while_listening` does for the
    one-shot probes; an answer counts whatever met the command. So is one whose reply may be
    the unanswered command before's, late (:func:`earlier_reply`): a sensor 80 ms late and
    deaf until it answers sent the retry before R-7.0-15's probe its '0<CR><LF>' 3 ms after
    the probe, which it never heard (parity-error or ack-trailing-space + replies-after-retry:
    "answered although 101.90 ms ... put it in standby", truth18). A control that maybe
    collided shows listening only by a valid reply (:func:`shows_listening`).

    ``stalled``: per exchange, a stall of the tool's own host over its decisive span (from
    what its marking counts from to the end of its read: :meth:`~conformance.sensor.
    session.SensorSession.stalled_since`), or None. Such a probe is no evidence either way
    (truth30): its answer may be another's reply read late, its silence a probe moved past
    the limit or a cut read; it is set aside with the stall named, and a rule left with no
    probe outside every stall is INCONCLUSIVE."""
    exchanges = list(exchanges)
    controls = [baseline] if isinstance(baseline, Exchange) else list(baseline)
    held = [(ex, stall) for ex, stall in zip(exchanges, stalled, strict=False) if stall]
    stalled_out = [ex for ex, _ in held]
    earlier = [ex for ex in exchanges if earlier_reply(ex)]
    aside = earlier + stalled_out
    answered = [ex for ex in exchanges if (ex.answered or heard_late(ex)) and not _among(ex, aside)]
    met = aside + [
        ex
        for ex in exchanges
        if not ex.answered
        and (ex.maybe_collided or late_elsewhere(ex))
        and not _among(ex, stalled_out)
    ]
    if answered:
        make = warned if should else failed
        return make(
            rid,
            f"answered although {why}: "
            + "; ".join(shown(e) if e.answered else late_shown(e) for e in answered[:3]),
            evidence=cite(answered),
            decision=decision,
            observed=len(exchanges),
        )
    if not any(shows_listening(ex) for ex in controls):
        return inconclusive(
            rid,
            "the sensor answered none of "
            + ", ".join(escape(ex.text) for ex in controls)
            + " either, so its silence here shows nothing"
            + collided_answers(controls),
        )
    heard = [ex for ex in exchanges if not _among(ex, met)]
    unheld = len(met) - len(held)
    aside = _set_aside(unheld, earlier, held)
    if not heard:
        what = "every command maybe collided with the sensor's characters; "
        if held and not unheld:
            what = f"no command outside a stall of the tool's host ({why}): "
        return inconclusive(rid, what + aside, evidence=[shown(ex) for ex in met[:3]])
    return passed(
        rid,
        f"stayed silent ({why}) to {len(heard)} command(s): "
        + ", ".join(escape(e.text) for e in heard)
        + (f"; {aside}" if met else ""),
        decision=decision,
        observed=len(heard),
    )


def _set_aside(count: int, earlier: list[Exchange], held: list[tuple[Exchange, Stall]]) -> str:
    """Why :func:`silent` set commands aside: ``count`` maybe collided or met by a late
    reply (the first ``earlier`` replies, :func:`earlier_reply`, shown), and the ``held``
    ones a stall of the tool's host was over, each with its stall (the first two)."""
    unheld = (
        f"{count} command(s) set aside (maybe collided, or a late reply naming another "
        "address or maybe the command before's came over it: may not have been heard)"
        + "".join(f"; {earlier_reply(ex)}" for ex in earlier[:2])
    )
    stalled = [
        f"{late_shown(ex) if heard_late(ex) and not ex.answered else shown(ex)}"
        f" set aside: {stall.why()}"
        for ex, stall in held[:2]
    ]
    return "; ".join(([unheld] if count or not held else []) + stalled)


def _among(ex: Exchange, exchanges: Iterable[Exchange]) -> bool:
    """Whether ``ex`` is one of ``exchanges`` (by identity: records compare by value)."""
    return any(ex is other for other in exchanges)


def silent_while_listening(
    rid: str,
    probes: Sequence[ControlledProbe],
    why: str,
    *,
    should: bool = False,
    decision: str | None = None,
) -> Finding:
    """Each probe must have drawn no reply; a silent probe counts only where the sensor
    answered the control sent the same way right after it (it was listening then). An
    answer is evidence whatever the control did; silence with every control unanswered is
    INCONCLUSIVE, "precondition not met"."""
    answered = [p.probe for p in probes if p.probe.answered]
    if answered:
        make = warned if should else failed
        return make(
            rid,
            f"answered although {why}: " + "; ".join(shown(e) for e in answered[:3]),
            evidence=[f"{shown(e)} at t={e.attempts[0].end:.3f} s" for e in answered],
            decision=decision,
            observed=len(answered),
        )
    unmet = listening(probes)
    if unmet is not None:
        return unmet.finding(rid)
    heard = [p for p in probes if p.listening]
    met = sum(p.probe.maybe_collided for p in probes)
    aside = len(probes) - len(heard) - met
    marking = heard[0].marking
    way = f" after {marking * 1e3:.0f} ms of marking" if marking is not None else ""
    return passed(
        rid,
        f"stayed silent ({why}) to {len(heard)} command(s) sent once after a break{way}, "
        "each followed by an a! sent the same way that it answered (and again after the "
        "next break): "
        + ", ".join(escape(p.probe.text) for p in heard)
        + (f"; {aside} probe(s) set aside (their control went unanswered)" if aside else "")
        + (f"; {met} probe(s) set aside (maybe collided: may not have been heard)" if met else ""),
        decision=decision,
        evidence=[shown(p.probe) for p in heard[:3]],
        observed=sum(len(p.exchanges) for p in heard),
    )


def undecided_if_late(tally: Tally, ex: Exchange, ids: Iterable[str]) -> bool:
    """An unanswered ``ex`` whose reply came after the tool stopped listening (it ran into the
    retries: a sensor whose every reply starts 80 ms late, deaf until then) is no "got no
    reply": undecided for ``ids`` on ``tally`` (INCONCLUSIVE unless something else FAILs them;
    R-7.0-10 judges the timing). True when it was; a silent exchange is left to FAIL. So is
    one answered with what may be the command before's late reply (:func:`answered_late`).
    And one no try of which went when the sensor must have been awake to hear it
    (:func:`~conformance.judges.wake_heard.unheard`: each soon after a break of its own)."""
    late = answered_late(ex)
    timed = late and not late.endswith(SET_ASIDE)  # a talk's next line is no late reply
    why = (f"{late} (R-7.0-10 judges its timing)" if timed else late) or unheard(ex)
    if not why:
        return False
    label = escape(ex.text)
    for rid in ids:
        tally.undecide(rid, label, why)
    return True


def _stalled(ex: Exchange, first_attempt: bool = False) -> str:
    """``0M!: the tool's host stalled 150 ms during this read`` where it stalled over the read
    of the try judged (the first, with ``first_attempt``): a silence it explains; else ''."""
    stall = ex.attempts[0].stall if first_attempt else ex.stall
    return f"{escape(ex.text)}: {stall.why()}" if stall is not None else ""


def first_answered_late(ex: Exchange) -> str:
    """What may be the first transmission's late reply ('' if nothing): the first try went
    unanswered and either the retries met DUT characters (:func:`late_reply`) or the retry's
    reply began too soon after it (under R-7.0-09's 7.93 ms) to answer it, so it began in
    answer to the try before. A sensor that waits 80 ms and is deaf until then answered
    the first aD0! after a service request 0 ms after the retry (truth11): "no reply" to the
    first aD0! was false. A reply timely to the retry is the retry's: ''."""
    first, judged = ex.attempts[0], ex.judged
    if first.reply_events or len(ex.attempts) < 2:
        return ""
    if text := late_reply(ex):
        return text
    if judged is first or not judged.reply_events or judged.command_end is None:
        return ""
    start = judged.reply_events[0].start
    if EARLY_WINDOW.inside(start - judged.command_end):
        return ""
    # and only if it began within the 87 ms a late start is believed after the try before:
    # later, it is the judged try's own reply, begun early (the uOS++ sensor, twenty-ninth
    # outside round, answers every command 7.67..8.35 ms after it: its reply to aD0! sent
    # after a break, 93 ms after the try before, was "answered only after its reply window")
    before = ex.attempts[ex.attempts.index(judged) - 1]
    slack = 2 * judged.reply_events[0].uncertainty
    if not late_start_after(start, judged.command_events, before, slack):
        return ""
    return decode_7e1(judged.reply_events)


def late_only(rid: str, ex: Exchange, what: str) -> Finding | None:
    """INCONCLUSIVE for ``rid`` if ``ex`` went unanswered in its windows but its reply came
    after them (:func:`late_reply`): the rule asks for ``what`` of a reply the tool did not
    take, so silence is no evidence against it (R-7.0-10 judges the timing). None otherwise:
    a silent or answered exchange is the caller's to judge; one answered with what may be the
    command before's late reply is not (:func:`answered_late`)."""
    late = answered_late(ex)
    if not late:
        return None
    return inconclusive(
        rid,
        f"{what}: {late} (R-7.0-10 judges its timing)",
        evidence=cite([ex]),
        observed=1,
    )


def late_among(rid: str, exchanges: Iterable[Exchange], what: str) -> Finding | None:
    """INCONCLUSIVE for ``rid`` if any of ``exchanges`` was answered only after its reply
    window (:func:`late_answer`), None otherwise: a measurement whose start or D reply ran
    into the retries delivered values the tool did not take, so a count short of the
    undisturbed one (``what``) is no evidence that it lost them. The replies-after-retry
    sensor's aD0! after an abort and after a break and zI! came 80 ms late, its values cut by
    the retry: "after the abort M delivered 0 values" and "C delivered 0 values after a break
    and zI!" were false FAILs (truth12)."""
    late = [(ex, text) for ex in exchanges if (text := answered_late(ex))]
    if not late:
        return None
    return inconclusive(
        rid,
        f"{what}, but " + "; ".join(text for _, text in late[:3]) + " (R-7.0-10 judges its timing)",
        evidence=cite([ex for ex, _ in late]),
        observed=len(late),
    )


def answered(
    rid: str,
    exchanges: Iterable[Exchange],
    why: str,
    *,
    first_attempt: bool = False,
    late_is_reply: bool = False,
) -> Finding:
    """Each exchange must have drawn a reply (on its first transmission, if asked). With
    ``late_is_reply`` (a rule that asks for a reply, not for its timing) an exchange answered
    only after the reply window is no silence: INCONCLUSIVE where no other is silent."""
    exchanges = list(exchanges)
    missing = [
        ex
        for ex in exchanges
        if not (ex.attempts[0].reply_events if first_attempt else ex.answered)
    ]
    late = [ex for ex in missing if late_is_reply and late_reply(ex)]
    # silence to tries none of which the sensor was awake to hear is no evidence; a rule on
    # the first transmission is about that wake-up itself
    deaf = [ex for ex in missing if ex not in late and not first_attempt and unheard(ex)]
    # and silence to the try judged whose read the host stalled over is the host's (truth27)
    read: dict[int, str] = {id(ex): _stalled(ex, first_attempt) for ex in missing}
    deaf += [ex for ex in missing if ex not in late and ex not in deaf and read[id(ex)]]
    missing = [ex for ex in missing if ex not in late and ex not in deaf]
    if deaf and not missing:
        return inconclusive(
            rid,
            "; ".join(unheard(e) or read[id(e)] for e in deaf[:3]),
            evidence=cite(deaf),
            observed=len(deaf),
        )
    if late and not missing:
        return inconclusive(
            rid,
            f"answered only after the reply window ({why}): "
            + "; ".join(late_shown(e) for e in late[:5])
            + " (R-7.0-10 judges its timing; a reply this rule could take was not heard)",
            evidence=cite(late),
            observed=len(late),
        )
    if missing:
        how = "on the first transmission " if first_attempt else ""
        return failed(
            rid,
            f"no reply {how}although {why}: " + "; ".join(escape(e.text) for e in missing[:5]),
            evidence=cite(missing),
            observed=len(exchanges),
        )
    return passed(
        rid,
        f"answered ({why}): "
        + ", ".join(shown(e) for e in exchanges[:4])
        + (f" (+{len(exchanges) - 4} more)" if len(exchanges) > 4 else ""),
        observed=len(exchanges),
    )


def continuous(
    exchanges: dict[int, tuple[Exchange, Exchange]], ids: Iterable[str]
) -> list[Finding]:
    """R0..R9 / RC0..RC9 replies: format like D replies, <=75 characters, CRC on RC, and the
    empty reply for an index the sensor does not serve (R-4.4.8.1-01/-03)."""
    tally = Tally(ids)
    unsupported = unread = 0
    for _index, pair in sorted(exchanges.items()):
        # an index whose other command returned values is served: the empty-reply rule is
        # not this pair's; else a late reply may be the unsupported index's, unread
        served = any(serves_continuous(ex) for ex in pair)
        for ex in pair:
            label = escape(ex.text)
            # a late reply's CRC (or its absence) is not judged either: it may be cut by the
            # retries; undecided, so the D replies' PASS does not stand for it (seed 4262,
            # continuous-crc-missing + replies-after-retry: R-4.4.12-02 PASSed on 0MC!/0CC!).
            # Nor is its empty form: replies-after-retry's aRC2!..aRC9! came only late, and
            # R-4.4.8.1-03 PASSed "conforms (8 checked: 0R2!..0R9!)" beside
            # unsupported-rc-without-crc, whose deviation is in those replies (truth19)
            crc_rule = "R-4.4.12-02" if ex.command is not None and ex.command.crc else "R-4.4.12-03"
            empty_rule = [] if served else ["R-4.4.8.1-03"]
            if undecided_if_late(tally, ex, ["R-4.4.8.1-01", crc_rule, *empty_rule]):
                unread += bool(empty_rule)
                continue
            here = through_stall(tally, ex.stall)  # what a stalled read shows is undecided
            if not ex.answered or ex.command is None:
                here.fail("R-4.4.8.1-01", label, f"{label} got no reply")
                continue
            crc = ex.command.crc
            if text_instead_of_values(ex, crc):
                # no values and no CRC to judge: only the empty-reply rule speaks
                unsupported += 1
                here.fail(
                    "R-4.4.8.1-03",
                    label,
                    f"unsupported {label} answered '{escape(ex.reply_text)}' (text, not "
                    f"'a{'<CRC>' if crc else ''}<CR><LF>')",
                )
                continue
            body, framing = split_line(ex.reply_text, crc_positions=3 if crc else 0)
            reply = parse_data_reply_for(body, ex.command, expected_address=ex.command.address)
            ids_here = [i for i in shown_reply_ids(ex.command, reply) if i != "R-4.4.8-01"]
            here.observe(
                label,
                framing + [v for v in reply.violations if v.requirement != "R-4.4.8-01"],
                ids=ids_here + ["R-4.4.8.1-01"],
            )
            if reply.crc and not reply.crc_ok:
                undecide_uncompared_crc(reply, tally, label)
            if not reply.values:
                unsupported += 1
                tally.observe(label, ids=["R-4.4.8.1-03"])
                expected = 1 + (3 if crc else 0)
                if len(body) != expected:  # its CRC's value is R-4.4.12-05's business
                    here.fail(
                        "R-4.4.8.1-03",
                        label,
                        f"unsupported {label} answered '{escape(ex.reply_text)}', not "
                        f"'a{'<CRC>' if crc else ''}<CR><LF>'",
                    )
            here.observe(
                label,
                check_data_sequence([reply], len(reply.values), VALUES_MAX),
                ids=["R-4.4.8.3-01"] if "R-4.4.8.3-01" in tally.ids else [],
            )
    if not unsupported and not unread:
        tally.not_applicable("R-4.4.8.1-03", "every R0..R9 returned values; no unsupported index")
    return tally.findings()


def na(rid: str, reason: str) -> Finding:
    return Finding(rid, Verdict.NA, reason)
