"""Section 4.4.1-4.4.4: a!, aI!, aAb!, and an answer to every basic command (Table 5)."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as judge
from conformance.protocol.commands import C_FAMILY, M_FAMILY
from conformance.protocol.responses import check_change_address_reply, split_line
from conformance.protocol.timing import ADDRESS_CHANGE_QUIET, TOLERANCE
from conformance.sensor.address_change import AddressChanger
from conformance.tool_recorder.records import Exchange
from conformance.verdicts import Finding, failed, inconclusive, passed

requirements = pytest.mark.requirements


@requirements("R-4.4.1-01")
@pytest.mark.preconditions("none")
def test_acknowledge_active(sensor, case):
    """a! returns exactly the address and CR LF."""
    case.expect(f"'{sensor.address}<CR><LF>'")
    ex = sensor.exchange("")
    case.evidence("a!", ex)
    case.add(judge.reply_only_address(ex, sensor.address, "R-4.4.1-01", "a!"))


@requirements("R-4.4.2-01", "R-4.4.2-02")
@pytest.mark.preconditions("none")
def test_identification(sensor, case):
    """aI! returns address, version, vendor, model, sensor version, optional field, CR LF."""
    case.expect("a + ll + 8-char vendor + 6-char model + 3-char version + 0..13 optional chars")
    ex = sensor.exchange("I")
    case.evidence("aI!", ex)
    _, findings = judge.identification(ex, sensor.address)
    case.extend(findings)


BASIC = (
    "",
    "I",
    *M_FAMILY,
    *C_FAMILY,
    *(f"D{i}" for i in range(10)),
    *(f"R{i}" for i in range(10)),
    *(f"RC{i}" for i in range(10)),
)


@requirements("R-4.4-01")
@pytest.mark.preconditions("none")
def test_every_basic_command_is_answered(sensor, case):
    """Every command of Table 5 draws a reply (the format of each is judged by its own rule)."""
    case.expect("a reply to each basic command; aAb! is judged in the address-change case")
    exchanges = []
    for code in BASIC:
        if code in M_FAMILY or code in C_FAMILY:
            exchanges.append(sensor.measurement(code).start)
        else:
            exchanges.append(sensor.exchange(code))
    if not sensor.shared:  # ?! on a shared bus draws every sensor's answer: not sent
        exchanges.append(sensor.once("query", sensor.master.query_address))
    case.evidence("Table 5 commands", exchanges)
    # a reply heard after the window is R-7.0-10's deviation, not silence (a late '00001' to
    # 0M1!..0M9! FAILed "no reply although it is a basic command")
    case.add(judge.answered("R-4.4-01", exchanges, "it is a basic command", late_is_reply=True))


def unanswered_change(request: Exchange, sent: str, note: str, evidence: list[str]) -> Finding:
    """R-4.4.4-01 on an ``aAb!`` none of whose tries was answered in its window: FAIL if the
    sensor stayed silent, INCONCLUSIVE if its reply came after the retries (a sensor whose
    every reply starts 80 ms late answered '9<CR><LF>' into the retry: R-7.0-10's deviation,
    and "got no reply" was false, truth11)."""
    if late := judge.late_answer(request):
        return inconclusive(
            "R-4.4.4-01", f"{late} (R-7.0-10 judges its timing; {note})", evidence=evidence
        )
    return failed("R-4.4.4-01", f"{sent} got no reply ({note})", evidence=evidence, observed=1)


@requirements("R-4.4.4-01", "R-4.4.4-02", "R-4.4.4-03")
@pytest.mark.preconditions("supported", address=("R-4.4.4-02",), listening=("R-4.4.4-03",))
def test_change_address(sensor, case):
    """aAb! moves the sensor to b, it answers there (after at most 1 s) and no longer at a."""
    case.expect(
        "reply 'b<CR><LF>'; answers at b within 1 s; silent at the old address; "
        "the original address is restored afterwards"
    )
    settable = sensor.address_change_supported()
    wrong = not settable and _answered_a_third_address(sensor, case)
    if not case.requires(
        "supported",
        precondition.served(settable, "the sensor's address is not software-settable"),
        only=("R-4.4.4-02", "R-4.4.4-03") if wrong else None,
    ):
        return
    original, target = sensor.address, sensor.spare_address()
    changer = AddressChanger(sensor.master, original)
    old = None
    heard = None
    elsewhere = None
    sensor.hearing_marking()  # found at the original address, before the change
    try:
        outcome = changer.change(target)
        if outcome.took:
            # the old address, then an a! at the new one sent the same way: silence at the
            # old address shows something only if the sensor was listening (R-7.0-05)
            heard = sensor.heard_probe(f"{original}!", control_address=target)
            old = heard.probe
            changer.exchanges.extend(heard.exchanges)
            if old.answered:
                # answered at the old address too: one that answers a! at any address shows
                # nothing by its answer at the new one (address-change-not-applied beside
                # answers-foreign-address, seed 4104: '9!' answered by a sensor left at '0'
                # PASSed R-4.4.4-01); an address no case gives it tells the two apart
                elsewhere = sensor.heard_probe(
                    f"{sensor.foreign_address()}!", control_address=target
                )
                changer.exchanges.extend(elsewhere.exchanges)
    finally:
        note = sensor.restore(changer)
    case.evidence("address change and restore", changer.exchanges)
    body, _ = split_line(outcome.request.reply_text)
    problems = check_change_address_reply(body, original, target)
    after = outcome.answered_after
    stayed = old is not None and old.answered
    anywhere = elsewhere is not None and (elsewhere.probe.answered or not elsewhere.listening)
    unshown = (
        f"'{target}!' was answered, but so was a! at the old address and "
        + (
            f"at '{elsewhere.probe.text[:-1]}', an address it never had"
            if elsewhere is not None and elsewhere.probe.answered
            else "no control was heard after a probe of an address it never had"
        )
        + ": the answer at the new address does not show the move"
    )
    request = [judge.cited(outcome.request)]
    if not outcome.request.answered:
        case.add(unanswered_change(outcome.request, f"{original}A{target}!", note, request))
    elif problems or not outcome.took:
        msg = "; ".join(v.message for v in problems) or "the sensor kept its old address"
        case.add(failed("R-4.4.4-01", f"{msg} ({note})", evidence=request, observed=1))
    elif after is None and stayed:
        case.add(
            failed(
                "R-4.4.4-01",
                f"replied '{target}' but stayed at '{original}' ({note})",
                evidence=request + judge.cite([*outcome.polls[-1:], old]),
                observed=2,  # the change and the answer at the old address
            )
        )
    elif anywhere:
        case.add(
            inconclusive(
                "R-4.4.4-01",
                f"{unshown} ({note})",
                evidence=request + judge.cite(elsewhere.exchanges),
                observed=1 + len(elsewhere.exchanges),
            )
        )
    else:
        reply = judge.escape(outcome.request.reply_text)
        case.add(passed("R-4.4.4-01", f"answered '{reply}'; {note}", observed=1))
    if not outcome.took:
        case.not_applicable(
            "the change did not happen, so what follows it cannot be judged",
            ["R-4.4.4-02", "R-4.4.4-03"],
        )
        return
    # the time to the first answer at the new address is judged only where it came there
    shown_at = precondition.answers_at(
        outcome.polls[-1] if after is not None and outcome.polls else None,
        target,
        "no answer at the new address to time",
        absent=True,  # nothing to time: the rule does not apply (R-4.4.4-03 FAILs it)
    )
    if after is None and not case.requires("listening", sensor.acknowledges(outcome.polls)):
        case.requires("address", shown_at)
        return  # silence to a! at the new address, from a sensor that answers no a!
    if after is None:
        case.add(
            failed(
                "R-4.4.4-03",
                f"never answered at the new address '{target}' within "
                f"{ADDRESS_CHANGE_QUIET + 3:.0f} s",
                evidence=request + judge.cite(outcome.polls[-1:]),
                observed=1 + len(outcome.polls),
            )
        )
        case.requires("address", shown_at)
        return
    case.requires("address", shown_at)
    if anywhere:
        case.add(
            inconclusive(
                "R-4.4.4-02",
                unshown,
                evidence=request + judge.cite(elsewhere.exchanges),
                observed=1 + len(elsewhere.exchanges),
            )
        )
    elif after > ADDRESS_CHANGE_QUIET + TOLERANCE + 0.25:  # one poll interval of slack
        case.add(
            failed(
                "R-4.4.4-02",
                f"ignored its new address for {after:.2f} s, more than "
                "the 1 s allowed after a change",
                measured_ms=after * 1e3,
                limit_ms=1000.0,
                evidence=request + judge.cite(outcome.polls[-1:]),
                observed=1 + len(outcome.polls),
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.4-02",
                f"answered at the new address {after:.3f} s after the "
                "change (1 s of silence is allowed)",
                observed=1,
            )
        )
    if stayed:
        case.add(
            failed(
                "R-4.4.4-03",
                f"still answered at the old address '{original}' ({judge.shown(old)})",
                evidence=request + [judge.cited(old)],
                observed=1,
            )
        )
    elif heard is None or not heard.listening:
        case.requires(
            "listening",
            precondition.Unmet(
                "listening",
                f"no a! at '{target}' sent like the probe of the old address '{original}' "
                "(one break, then once) was answered, so the silence at the old address "
                "shows nothing",
                tuple(judge.cite(heard.exchanges)) if heard is not None else (),
            ),
        )
    elif case.requires("listening", None):
        case.add(
            passed(
                "R-4.4.4-03",
                f"answered only at '{target}' after the change "
                "(keeping it over a power cycle is not tested: no power control)",
                observed=2,  # the silent old address and the answered new one
            )
        )


def _answered_a_third_address(sensor, case) -> bool:
    """Whether the aAb! that found the address not settable drew a reply naming neither b nor
    the unchanged address: R-4.4.4-01 allows only those two, so that reply FAILs it whatever
    the sensor can do (a PIC firmware answered '0' to 'jA9!' from the wrong EEPROM slot, and
    moved to '9': the tool said N/A "not software-settable")."""
    trial = sensor.address_trial
    if trial is None or not trial.request.answered:
        return False
    body, _ = split_line(trial.request.reply_text)
    problems = check_change_address_reply(body, trial.original, trial.target)
    if not problems or body == trial.original:
        return False
    case.evidence("the address-change trial", [trial.request])
    reasons = "; ".join(v.message for v in problems)
    detail = f"{reasons} (found trying whether it is settable; {trial.note})"
    case.add(failed("R-4.4.4-01", detail, evidence=[judge.cited(trial.request)], observed=1))
    return True
