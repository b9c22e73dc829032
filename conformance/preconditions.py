"""Declared preconditions: what the wire must show before a case may judge (issue 18).

A verdict about a device rests on a state of that device: awake when a silence is judged, a
measurement still running when a break is to abort it, values in the buffer when they are to
be compared. When the wire does not show that state, a PASS or a FAIL would be about nothing,
so the requirement is INCONCLUSIVE, "precondition not met: <code>: ...", with the events that
show why. Every case declares its preconditions (``@pytest.mark.preconditions``, read by
:func:`declared`), each with a reason code of :data:`CODES`; the checks over transcript
events and records live here, in one place, and :meth:`conformance.case.Case.requires`
applies their outcome, so no case rebuilds the rule or its wording.

The marker: ``@preconditions("supported", pending=("R-4.4.5.1-01",))``. A positional code
guards every requirement of the case; a keyword code guards the requirements it names. A case
that genuinely needs nothing beyond a device answering at its address declares ``"none"``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Protocol

from .judges.cite import cited, heard, shown
from .judges.late_before import heard_late, late_shown
from .judges.reply_validity import check_reply
from .judges.support import serves_measurement
from .protocol.timing import CHAR_TIME, STANDBY_MARKING, TOLERANCE
from .tool_recorder.records import Exchange, Measurement
from .transcript import TOOL, Event, decode_7e1, escape
from .verdicts import Finding, inconclusive, not_applicable

MARKER = "preconditions"
MARKER_HELP = (
    "preconditions(*codes, **code_to_requirements): what the wire must show before the case "
    "judges (conformance/preconditions.py CODES); 'none' if nothing"
)

#: Every reason code, with what the wire must show for it to hold.
CODES: Mapping[str, str] = MappingProxyType(
    {
        "none": "nothing beyond a device that answers at its address",
        "listening": "the sensor was listening when a probe whose silence is judged went out:"
        " it answered an a! sent the same way (one break, the same marking, once)",
        "awake": "a command whose silence is judged went out while a compliant sensor must"
        " still be awake: less than 100 ms of marking after the break",
        "standby": "the sensor was shown in standby: it ignored an a! sent without a break"
        " after more than 100 ms of marking",
        "pending": "the measurement was still running when the break or command meant to"
        " disturb it started: no service request or other text before it, ttt not elapsed",
        "aborted": "the abort the rule is about was shown: no service request after the break"
        " of a measurement that raises one undisturbed",
        "buffered": "the data buffer held values to compare or to lose",
        "supported": "the feature was shown served by a well-formed answer of its own kind"
        " (judges/support.py), or declared so",
        "address": "the address judged against is the one the sensor has now",
        "recorder": "the recorder was made to act in the scenario the rule is about",
        "heard": "the traffic the rule is about was heard on the line (a passive run judges"
        " only what it overheard; none heard is INCONCLUSIVE, never a PASS)",
        "alone": "the sensor was alone on the line: on a bus shared with other sensors ?! (and"
        " addresses they hold) would draw their answers too, so such probes are not sent",
        "others": "other sensors on the line answered the traffic a bus case is about, and the"
        " sensor judged was shown listening just before (a bus of one shows nothing)",
    }
)


#: How a passive run says a rule's traffic is not in the recording (offline/heard.py).
NOT_SEEN = "not seen in the recording"


class PreconditionError(ValueError):
    """A declaration that names an unknown code or a requirement the case does not judge."""


@dataclass(frozen=True)
class Unmet:
    """A precondition the wire did not show: its code, why, and the evidence lines."""

    code: str
    detail: str
    evidence: tuple[str, ...] = ()
    #: the rule whose deviation probably removed the precondition (root_causes.py links it)
    consequence_of: str | None = None
    #: the capability is absent (an optional feature not served, by declaration or on the
    #: wire): its rules do not apply, N/A, rather than undecided
    absent: bool = False
    #: the stimulus happened in part (a scenario cut short): a FAIL on what the wire did show
    #: stands beside the INCONCLUSIVE; a PASS or WARN, which would speak for the whole, does not
    partial: bool = False

    def __post_init__(self) -> None:
        if self.code not in CODES:
            raise PreconditionError(f"unknown precondition {self.code!r}")

    @property
    def text(self) -> str:
        return f"precondition not met: {self.code}: {self.detail}"

    def finding(self, rid: str) -> Finding:
        if self.absent:
            return not_applicable(rid, self.text)
        return inconclusive(
            rid, self.text, evidence=list(self.evidence), consequence_of=self.consequence_of
        )


@dataclass(frozen=True)
class Declaration:
    """A case's declared preconditions: code -> the requirements it guards."""

    guards: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def declared(self) -> bool:
        return bool(self.guards)

    def guarded(self, code: str) -> tuple[str, ...]:
        return self.guards.get(code, ())

    def covered(self) -> set[str]:
        return {rid for rids in self.guards.values() for rid in rids}


def declaration(
    args: Iterable[str], kwargs: Mapping[str, Iterable[str]], requirements: Sequence[str]
) -> Declaration:
    """Build and check a declaration from the marker's arguments (PreconditionError if it
    names an unknown code or a requirement the case does not judge)."""
    guards: dict[str, tuple[str, ...]] = {}
    for code in args:
        guards[code] = tuple(requirements)
    for code, rids in kwargs.items():
        rids = (rids,) if isinstance(rids, str) else tuple(rids)
        guards[code] = tuple(dict.fromkeys(guards.get(code, ()) + rids))
    unknown = sorted(set(guards) - set(CODES))
    if unknown:
        raise PreconditionError(f"unknown precondition code(s) {unknown}; known: {sorted(CODES)}")
    stray = sorted({r for rids in guards.values() for r in rids} - set(requirements))
    if stray:
        raise PreconditionError(f"preconditions guard {stray}, which the case does not judge")
    if "none" in args and len(guards) > 1:
        # 'none' for named requirements may stand beside codes guarding the others
        raise PreconditionError("'none' cannot stand beside other preconditions")
    return Declaration(MappingProxyType(guards))


def declared(item: Any, requirements: Sequence[str]) -> Declaration:
    """The declaration on a pytest item (an empty one when it has no marker)."""
    marker = item.get_closest_marker(MARKER)
    if marker is None:
        return Declaration()
    return declaration(marker.args, marker.kwargs, requirements)


def declared_on(fn: Any, requirements: Sequence[str]) -> Declaration:
    """The declaration on a case function itself (a test that runs one case by hand)."""
    marks = [m for m in getattr(fn, "pytestmark", []) if m.name == MARKER]
    if not marks:
        return Declaration()
    return declaration(marks[0].args, marks[0].kwargs, requirements)


# -- the checks, from the wire --------------------------------------------------------------


class ControlledProbe(Protocol):
    """A one-off probe and the ``a!`` control sent the same way right after it."""

    probe: Exchange
    control: Exchange | None
    recheck: Exchange | None  # the control again after one more break (silent probes)
    marking: float | None

    @property
    def listening(self) -> bool: ...

    @property
    def woke_differently(self) -> bool: ...


def alone(others: Iterable[str], what: str) -> Unmet | None:
    """``what`` (``?!``, an address sweep) goes out only to a sensor alone on the line."""
    shared = sorted(others)
    if not shared:
        return None
    return Unmet(
        "alone",
        f"{what} not sent: the sensor shares the line with the sensor(s) at "
        f"{', '.join(shared)}, who would answer too",
    )


def listening(probes: Sequence[ControlledProbe]) -> Unmet | None:
    """Silence to one-off probes counts only where the sensor answered the control sent the
    same way right after one of them."""
    if any(p.listening for p in probes):
        return None
    if varied := [p for p in probes if p.woke_differently]:
        return Unmet(
            "listening",
            "the sensor answered the a! sent like the probe (one break, then once) after one "
            "break and not after the next: it wakes differently from break to break "
            f"(R-7.0-05), so its silence to {len(probes)} probe(s) shows nothing",
            tuple(
                shown(ex)
                for p in varied[:2]
                for ex in (p.probe, p.control, p.recheck)
                if ex is not None
            ),
        )
    met = [p.probe for p in probes if p.probe.maybe_collided]
    if met and all(p.control is not None and shows_listening(p.control) for p in probes):
        return Unmet(
            "listening",
            f"every probe maybe collided with the sensor's characters ({len(met)}), so it "
            "may not have been heard and its silence shows nothing",
            tuple(shown(ex) for ex in met[:3]),
        )
    return Unmet(
        "listening",
        "the sensor answered none of the a! controls sent like its probes (one break, then "
        f"once), so its silence to {len(probes)} probe(s) shows nothing"
        + collided_answers(p.control for p in probes if p.control is not None),
        tuple(shown(p.probe) for p in probes[:3]),
    )


def heard_one_shot(marking: float | None, what: str) -> Unmet | None:
    """A one-off command for another address is heard only by a sensor shown to answer a
    one-shot ``a!`` after a break (:meth:`SensorSession.hearing_marking`, ``marking``; None:
    no marking worked), so its silence or its effect shows nothing otherwise."""
    if marking is not None:
        return None
    return Unmet(
        "listening",
        f"the sensor answered no one-shot a! after a break, so it may not have heard {what}",
    )


def awake(marking: float, uncertainty: float) -> Unmet | None:
    """A command went out while a compliant sensor must still be listening: less than 100 ms
    of marking (less the tolerance and the link's uncertainty) after the break."""
    if marking + uncertainty < STANDBY_MARKING - TOLERANCE:
        return None
    return Unmet(
        "awake",
        f"the command went out {marking * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} ms of marking "
        f"after the break, not surely within the {STANDBY_MARKING * 1e3:.0f} ms after which a "
        "compliant sensor is back in standby, so its silence proves nothing",
        (f"{marking * 1e3:.2f} ms of marking after the break",),
    )


def standby(check: Exchange, marking: float) -> Unmet | None:
    """The sensor is in standby when it ignored ``check``, an ``a!`` sent without a break
    after ``marking`` s of marking; one that answered it never sleeps (R-7.0-15). So does
    one that answered it late (``check.heard_late``, :func:`heard_late`): never-standby +
    replies-after-retry's '0<CR><LF>' came 80 ms after the check, past its window, and the
    sensor that never sleeps was taken as asleep (R-7.0-04 judged, truth18)."""
    if not check.answered and not heard_late(check):
        return None
    answer = shown(check) if check.answered else late_shown(check)
    return Unmet(
        "standby",
        "the sensor was not shown in standby (it answered a! without a break after "
        f"{marking * 1e3:.0f} ms of marking: {answer})",
        (answer,),
        consequence_of="R-7.0-15",
    )


def pending(
    start: Exchange, ttt: float, before: list[Event], disturbance: Event, what: str = "break"
) -> Unmet | None:
    """The measurement ``start`` began was still running when ``disturbance`` (a break or the
    first event of a command) started: it was answered, nothing came from the sensor between
    its reply and the disturbance (a service request means the data were ready), and ttt had
    not run out."""
    if not start.answered:
        return Unmet("pending", f"the measurement never started: {shown(start)}", (cited(start),))
    sent = [e for e in before if e.origin != TOOL and e.start < disturbance.start]
    when = f"t={disturbance.start:.4f} s: {what}"
    if sent:
        return Unmet(
            "pending",
            f"the sensor had finished before the {what} (it sent "
            f"'{escape(decode_7e1(sent))}' first), so nothing was left to abort",
            (cited(start), heard(sent, "then"), when),
        )
    reply_end = start.reply_events[-1].end if start.reply_events else None
    if reply_end is not None and disturbance.start - reply_end >= ttt:
        return Unmet(
            "pending",
            f"the {what} came {disturbance.start - reply_end:.3f} s after the reply, when "
            f"ttt ({ttt:g} s) had already run out",
            (cited(start), when),
        )
    return None


def aborted(undisturbed: Measurement, service_requests_after: list[list[Event]]) -> Unmet | None:
    """An abort is shown when the measurement raises a service request undisturbed and none
    came after the break (``service_requests_after``: the ones heard, as events)."""
    if undisturbed.service_request_end is None:
        return Unmet(
            "aborted",
            f"the undisturbed {undisturbed.command.text()[1:-1]} raised no service request "
            "either, so its absence after the break proves no abort",
            (cited(undisturbed.start),),
        )
    if service_requests_after:
        return Unmet(
            "aborted",
            "the break aborted nothing: a service request followed it",
            (heard(service_requests_after[0], "service request after the break"),),
        )
    return None


def buffered(
    m: Measurement | None, what: str = "measurement", detail: str | None = None
) -> Unmet | None:
    """The buffer holds values when a measurement delivered at least one (``detail``, if
    given, says what the missing values leave unjudged)."""
    if m is not None and m.value_count:
        return None
    evidence = (cited(m.start),) if m is not None else ()
    return Unmet("buffered", detail or f"no {what} delivered values to compare", evidence)


def buffered_any(
    ms: Sequence[Measurement], what: str = "measurement", detail: str | None = None
) -> Unmet | None:
    """:func:`buffered` over several measurements: one that delivered values is enough."""
    first = next((m for m in ms if m.value_count), ms[0] if ms else None)
    return buffered(first, what, detail)


def supported(m: Measurement, what: str | None = None) -> Unmet | None:
    """A measurement command is served when its start reply is well formed and announces a
    value (:func:`conformance.judges.support.serves_measurement`)."""
    if serves_measurement(m):
        return None
    name = what or m.command.text()
    return Unmet(
        "supported",
        f"{name} was not shown served (no well-formed reply announcing values): {shown(m.start)}",
        (cited(m.start),),
    )


def served(present: bool, detail: str, evidence: Iterable[str] = ()) -> Unmet | None:
    """An optional capability is judged only where it was shown served (a well-formed answer
    of its own kind, judges/support.py) or declared; ``detail`` says what was missing. Its
    rules are N/A then, not undecided: the capability is absent, not unobserved."""
    if present:
        return None
    return Unmet("supported", detail, tuple(evidence), absent=True)


def shown_supported(present: bool, detail: str, evidence: Iterable[str] = ()) -> Unmet | None:
    """A capability the rule needs was not shown although the sensor must (or says it does)
    have it: INCONCLUSIVE, since its absence is another rule's FAIL, not this one's N/A."""
    if present:
        return None
    return Unmet("supported", detail, tuple(evidence))


def answers_at(
    control: Exchange | None, address: str, what: str, *, absent: bool = False
) -> Unmet | None:
    """The address judged against is the one the sensor has now: ``control``, a command at
    ``address`` sent just before or after, was answered from it (``absent``: what the rule
    is about did not happen at all, N/A rather than undecided)."""
    if control is not None and control.answered:
        return None  # what its reply starts with is the rule's to judge, not the precondition's
    return Unmet(
        "address",
        f"the sensor was not shown at address '{address}' ({what})"
        + (f": {shown(control)}" if control is not None else ""),
        (cited(control),) if control is not None else (),
        absent=absent,
    )


def silence_listening(probes: Sequence[ControlledProbe]) -> Unmet | None:
    """:func:`listening` where silence is judged: a probe that was answered is evidence
    whatever its control did, so only all-silent probes need a listening sensor."""
    if any(p.probe.answered for p in probes):
        return None
    return listening(probes)


def shows_listening(control: Exchange) -> bool:
    """Whether ``control`` (a command at the sensor's own address) shows the sensor was
    listening: it was answered, and its answer is no talk-over. Where the judged attempt
    maybe collided (sensor characters met it, :attr:`Exchange.maybe_collided`), what came
    after may be the rest of the stray characters that met it (a stray burst read across the
    command's end within the stamps' uncertainty), not an answer: it shows listening only if
    it is a valid reply to the control by the judges' rules (:func:`check_reply`, each
    character's own stamp uncertainty allowed in its gaps). A one-shot control unanswered in
    its window whose late reply the longer listen for a sensor seen late heard
    (:attr:`Exchange.heard_late`, :meth:`SensorSession.hear_late`) shows it listening too."""
    if not control.answered:
        return heard_late(control)  # a late reply naming another address is not its answer
    if not control.maybe_collided:
        return True
    judged = control.judged
    events = judged.reply_events
    end = judged.command_end
    slack = max(e.uncertainty for e in events)
    problem = check_reply(
        control.command,
        events,
        address=control.text[:1],
        command_end=events[0].start if end is None else end,
        gap_limit=CHAR_TIME + TOLERANCE + slack,
        crc_expected=None,
    )
    return problem is None


def collided_answers(controls: Iterable[Exchange]) -> str:
    """For a detail: the answers :func:`shows_listening` set aside, if any."""
    aside = sum(ex.answered and not shows_listening(ex) for ex in controls)
    if not aside:
        return ""
    return (
        f" ({aside} answer(s) set aside: maybe collided, and no valid reply, so possibly "
        "the characters that met the command)"
    )


def answered_control(controls: Sequence[Exchange], what: str) -> Unmet | None:
    """Silence is evidence only from a sensor shown listening: one of ``controls`` (its own
    address, asked the same way) was answered (:func:`shows_listening`: not by what may be
    the stray characters that met it)."""
    if any(shows_listening(ex) for ex in controls):
        return None
    return Unmet(
        "listening",
        "the sensor answered none of its own-address controls ("
        + ", ".join(escape(ex.text) for ex in controls)
        + f"), so its silence {what} shows nothing"
        + collided_answers(controls),
        tuple(cited(ex) for ex in controls[:3]),
    )


def answered_at_each_wake(controls: Sequence[Exchange], what: str) -> Unmet | None:
    """:func:`answered_control` for ``controls`` sent the same way after breaks in a row:
    every one must be answered. A sensor answered after one break and not after the next
    wakes differently from break to break (slow-wake-every-other), so the probe's break
    shows nothing of it: its control was answered after another break (truth36)."""
    unmet = answered_control(controls, what)
    if unmet is not None or all(shows_listening(ex) for ex in controls):
        return unmet
    return Unmet(
        "listening",
        "the sensor answered its own-address control ("
        + escape(controls[0].text)
        + ") after one break and not after the next: it wakes differently from break to "
        f"break (R-7.0-05), so its silence {what} shows nothing",
        tuple(cited(ex) for ex in controls[:3]),
    )


def acknowledges(probes: Sequence[Exchange], acknowledged: bool, address: str) -> Unmet | None:
    """Silence to an ``a!`` probe shows something only from a sensor that answers ``a!``:
    ``acknowledged``, one of its ``a!`` at ``address`` drew a reply (valid or not) somewhere
    in the run. A sensor that answers its other commands but never ``a!`` (R-4.4.1-01 FAILs that)
    says nothing about waking or about an address by not answering one. An ``a!`` of
    ``probes`` that maybe collided counts only with a valid reply (:func:`shows_listening`):
    what came after the characters that met it may be their rest, not an answer (the
    engine's ``acknowledged`` already leaves out an ``a!`` its characters met)."""
    if acknowledged or any(shows_listening(ex) for ex in probes):
        return None
    return Unmet(
        "listening",
        f"the sensor answered no {address}! anywhere in the run (R-4.4.1-01), so its silence "
        "to the a! probe shows nothing" + collided_answers(probes),
        tuple(cited(ex) for ex in probes[:2]),
    )


def woke(wakes: Sequence[Exchange]) -> Unmet | None:
    """The sensor was shown awake: it answered one of the wake-up ``a!`` (break, a!,
    retries) sent before the probes whose silence or answer is judged. A wake-up whose
    judged attempt maybe collided counts only with a valid reply (:func:`shows_listening`):
    what came after the characters that met it may be their rest, not an answer."""
    if any(shows_listening(ex) for ex in wakes):
        return None
    return Unmet(
        "awake",
        "the sensor did not answer the wake-up a!" + collided_answers(wakes),
        tuple(cited(ex) for ex in wakes[:2]),
    )


def silence_awake(answered: bool, marking: float, uncertainty: float) -> Unmet | None:
    """:func:`awake` where it matters: a command that was answered judges no silence, so the
    marking before it needs no bound."""
    return None if answered else awake(marking, uncertainty)


def acted(errors: Sequence[str]) -> Unmet | None:
    """The recorder was made to act in the scenarios the rule is about: each ran to its end
    (``errors``: why one did not). A driver that failed before the recorder said anything
    stops the run (RecorderSession._check_setup), so what is left is a scenario cut short:
    what the recorder did send is still judged (a FAIL stands), but no PASS speaks for it."""
    if not errors:
        return None
    return Unmet("recorder", "; ".join(errors), partial=True)


def overheard(items: Sequence[Any], what: str) -> Unmet | None:
    """A passive run judges only traffic it overheard: ``items`` (the exchanges, commands or
    measurements of the rule's kind in the recording) is not empty; ``what`` names them."""
    if items:
        return None
    return Unmet("heard", f"{NOT_SEEN}: {what}")
