"""Judges of the stateful exploration (``conformance.sensor.exploration``): every check it
made of a reply, judged, and the run's breach and tally turned into Findings.

The exploration only drives the sensor and records what each checked step showed as an
:class:`Observation`. It still asks :func:`judge` after each one, because the first breach
ends the exploration (the steps after it would start from whatever state the breach left,
and a certificate must send the same stimuli every time); everything a verdict says, and
why, is decided here, from the records alone, so a saved record can be judged again.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Literal

from ..protocol.crc import is_crc_char
from ..protocol.responses import holds_values, parse_data_reply, split_line
from ..transcript import escape
from ..verdicts import Finding, failed, inconclusive, passed
from .cite import listed
from .measurements import uncompared_crc

#: The requirements the exploration judges, in the order their findings are reported.
IDS = ("R-4.0-01", "R-4.3-01", "R-4.2-03", "R-4.4.12-05", "R-4.4.12-06", "R-4.4.5-10")

#: The requirements whose checks here judge one clause of the rule only: a repeated D0
#: shows repeated reads identical across whatever random steps fell between, not retention
#: across the breaks, standby and aI!/a!/aRn! the rule names (the retention case sends
#: those); the framing check reads replies only, never the service requests R-4.2-03 names
#: ("service requests included"; the whole-run framing judge reads those). Their PASS
#: stands beside that case's, never for it (results.counted), nor alone
#: (results.partial_only). R-4.3-01 (a reply's first character is the address) and
#: R-4.0-01, R-4.4.12-05/-06 (each foreign command, each claimed CRC) are checked whole on
#: every reply or command they count.
PARTIAL = frozenset({"R-4.4.5-10", "R-4.2-03"})

#: What an observation checks: silence to a foreign address, the framing and address of a
#: reply, a claimed CRC, or a D0 repeated with no measurement between.
Check = Literal["foreign", "framing", "crc", "repeat"]


@dataclass(frozen=True)
class Observation:
    """One checked step of the exploration: the command sent, the reply heard, and the
    context its check needs (kept with it, so the judgement needs no machine state)."""

    check: Check
    command: str  # the command as sent (Exchange.text)
    reply: str  # the reply as heard (Exchange.reply_text); '' when silent
    address: str = ""  # framing: the sensor's address; foreign: the address commanded
    answered: bool = True  # foreign: whether anything answered
    marked: bool = False  # foreign: sent with a marking the sensor was shown to hear
    collided: bool = False  # foreign: sensor characters met it (it may not have been heard)
    previous: str | None = None  # repeat: the D0 reply since the last measurement command
    #: repeat: a foreign measurement command sent since ``previous`` whose silence shows
    #: nothing (the sensor was seen to start its replies late): it may have been taken
    unheard: str = ""
    #: repeat: the reply taken may be an earlier command's, late (``late_before.answered_late``)
    late: str = ""
    #: the reply's read was held up by a stall of the tool's own host (its
    #: :meth:`~conformance.links.host_stall.Stall.why`): what it shows may be the host's
    stalled: str = ""


@dataclass(frozen=True)
class Breach:
    """An invariant the sensor broke: the requirement and what was seen."""

    requirement: str
    message: str


@dataclass(frozen=True)
class Judgement:
    """What one observation counted as a check, and the breach it showed (if any)."""

    checked: tuple[str, ...]
    breach: Breach | None = None
    #: what would have been a breach, seen in a read the tool's host stalled over: the rule
    #: is INCONCLUSIVE for it (unless another observation breaks it), and the exploration
    #: goes on (truth27: a clean emulator FAILed R-4.2-03 on a reply the pause cut)
    undecided: Breach | None = None


def _foreign(obs: Observation) -> Judgement:
    """Silence to another address counts only when the command went out the way the sensor
    was shown to hear one and met none of its characters (else silence says nothing: it may
    not have been heard); an answer always counts, and breaks."""
    heard = obs.marked and not obs.collided
    checked = ("R-4.0-01",) if heard or obs.answered else ()
    if not obs.answered:
        return Judgement(checked)
    message = (
        f"answered {escape(obs.command)}, a command for "
        f"address '{obs.address}', with '{escape(obs.reply)}'"
    )
    return Judgement(checked, Breach("R-4.0-01", message))


def _framing(obs: Observation) -> Judgement:
    """Every reply ends in CR LF and starts with the sensor's address (CR LF first: a reply
    cut short may also lack its address)."""
    body, framing = split_line(obs.reply)
    checked = ("R-4.2-03", "R-4.3-01")
    label = escape(obs.command)
    if [v for v in framing if v.requirement == "R-4.2-03"]:
        message = f"reply to {label} '{escape(obs.reply)}' does not end in CR LF"
        return Judgement(checked, Breach("R-4.2-03", message))
    if body[:1] != obs.address:
        message = f"reply to {label} starts with '{escape(body[:1])}', not '{obs.address}'"
        return Judgement(checked, Breach("R-4.3-01", message))
    return Judgement(checked)


def _crc(obs: Observation) -> Judgement:
    """A CRC the reply claims is right (05) and well encoded (06), in that order: a wrong
    value ends the check before its encoding is counted. A reply that claims none is left to
    the D-reply cases, which judge whether one was due."""
    body, _ = split_line(obs.reply)
    if len(body) < 4 or not all(is_crc_char(c) for c in body[-3:]):
        return Judgement(())
    reply = parse_data_reply(body, crc_expected=True, limit=75)
    checked: tuple[str, ...] = ()
    for rid in ("R-4.4.12-05", "R-4.4.12-06"):
        if rid == "R-4.4.12-05" and uncompared_crc(reply):
            continue  # (seed 4198) a CRC encoded as no CRC-16's is no check of its value
        checked += (rid,)
        bad = [v for v in reply.violations if v.requirement == rid]
        if bad:
            message = f"reply to {escape(obs.command)}: {bad[0].message}"
            return Judgement(checked, Breach(rid, message))
    return Judgement(checked)


def _repeat(obs: Observation) -> Judgement:
    """D0 read again with no measurement between gives the same reply. It counts as a check
    only where the earlier D0 held values (a digit past the address; CRC characters never
    are digits): the first D0 after a measurement, or a buffer that was empty, has nothing
    a lost buffer would change, and a sensor that never delivered a value PASSed "held over
    48 checks" (continuous-overwrites-data beside d0-empty, seed 4066). Changed data after a
    foreign measurement command whose silence shows nothing (``unheard``) are no check
    either: the sensor may have taken it as its own, which is R-4.0-01's deviation, not lost
    data. answers-old-address + replies-after-retry: 9M!, to the address the sensor had
    been moved from and still answers at, started a measurement whose reply, 80 ms late,
    the next break cut; D0 then read '0<CR><LF>' and R-4.4.5-10 FAILed (truth21)."""
    if obs.previous is None or not holds_values(obs.previous) or obs.late:
        # a reply taken that may be an earlier command's, late, is no read of D0 at all
        # (replies-after-retry + parity-error behind an echoing 16 ms USB link: 0D1!'s
        # late '0+12.50...' taken by the 0D0! after it FAILed "D0 gave ..., then ...",
        # outside28)
        return Judgement(())
    checked = ("R-4.4.5-10",)
    if obs.reply == obs.previous:
        return Judgement(checked)
    if obs.unheard:
        return Judgement(())
    message = (
        f"D0 gave '{escape(obs.previous)}', then '{escape(obs.reply)}' with no measurement between"
    )
    return Judgement(checked, Breach("R-4.4.5-10", message))


_JUDGES: dict[str, Callable[[Observation], Judgement]] = {
    "foreign": _foreign,
    "framing": _framing,
    "crc": _crc,
    "repeat": _repeat,
}


#: How many judgements :func:`judge` keeps (a few hundred distinct observations a run)
JUDGED_MAX = 4096
_JUDGED: dict[Observation, Judgement] = {}


def judge(obs: Observation) -> Judgement:
    """The judgement of one observation (pure: the same record always judges the same).

    Kept, and given again for an equal record: each observation is judged as the
    exploration makes it, then again by every reader of the run (``Exploration.broken``,
    :func:`held_findings`' breach and count), and a fault-matrix row judges the same run
    again through its capture (issue 22, matrix23: six judgements an observation, a CRC
    parsed in each). The table is emptied when full, as ``parse_command``'s is."""
    judged = _JUDGED.get(obs)
    if judged is None:
        if len(_JUDGED) >= JUDGED_MAX:
            _JUDGED.clear()
        judged = _JUDGES[obs.check](obs)
        if obs.stalled and judged.breach is not None:
            b = judged.breach
            held = Breach(b.requirement, f"{b.message}, but {obs.stalled}")
            judged = Judgement((), undecided=held)
        _JUDGED[obs] = judged
    return judged


def first_breach(observations: Iterable[Observation]) -> Breach | None:
    """The first breach among ``observations``: hypothesis replays a failing example to
    confirm it, and a real device, whose state moved on, may then behave otherwise; the
    first observation stands."""
    for obs in observations:
        breach = judge(obs).breach
        if breach is not None:
            return breach
    return None


def checks(observations: Iterable[Observation]) -> dict[str, int]:
    """How many checks each requirement got, over every observation (replays included)."""
    counted = {rid: 0 for rid in IDS}
    for obs in observations:
        for rid in judge(obs).checked:
            counted[rid] += 1
    return counted


def broken_finding(breach: Breach, failing_sequence: Sequence[str], exchanges: int) -> Finding:
    """The FAIL for the invariant that ended the exploration, with the last steps that led
    to it as evidence (the whole sequence would drown the report)."""
    seq = " ; ".join(failing_sequence[-12:])
    return failed(
        breach.requirement,
        breach.message,
        evidence=[f"failing sequence (last steps): {seq}"],
        observed=max(exchanges, 1),  # the step that broke it, at least
    )


def held_findings(observations: Sequence[Observation], steps: int) -> list[Finding]:
    """A PASS for every requirement checked and not broken, an INCONCLUSIVE for every one no
    step exercised (the broken one has its FAIL from :func:`broken_finding`)."""
    breach = first_breach(observations)
    counted = checks(observations)
    undecided: dict[str, list[str]] = {}
    for obs in observations:
        if (held := judge(obs).undecided) is not None:
            undecided.setdefault(held.requirement, []).append(held.message)
    out: list[Finding] = []
    for rid in IDS:
        if breach is not None and rid == breach.requirement:
            continue
        if rid in undecided:  # never a PASS beside what a stalled read may have hidden
            said = undecided[rid]
            out.append(inconclusive(rid, listed(said), observed=counted[rid] + len(said)))
        elif counted[rid]:
            detail = f"held over {counted[rid]} checks in {steps} random steps"
            out.append(passed(rid, detail, observed=counted[rid], partial=rid in PARTIAL))
        else:
            out.append(inconclusive(rid, f"no step of the {steps} exercised it"))
    return out
