"""Section 4.0-4.3 and 4.4.3: addresses, foreign addresses, the ?! query."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as judge
from conformance.protocol.commands import ADDRESS_CHARS, Kind
from conformance.sensor.session import HeardProbe, Sweep
from conformance.tool_recorder.records import Exchange
from conformance.verdicts import Finding, failed, inconclusive, passed

requirements = pytest.mark.requirements


def spare_addresses(sensor, count: int = 3) -> list[str]:
    """Addresses that are not the DUT's, for the foreign-address probes: the spare address
    the address-change cases use first (a sensor must not keep answering it), then others;
    on a shared bus never one another sensor holds (its answer would not be the DUT's)."""
    spare = sensor.spare_address()
    taken = {sensor.address, spare, *sensor.others}
    return [spare] + [a for a in "0123456789" if a not in taken][: count - 1]


def ends_in_own_address(sensor) -> str:
    """A valid command for an address no sensor on the line has whose last character before
    '!' is the DUT's address: ``zD5!`` (a D read) at '5', ``zA5!`` (a change to '5') where the
    address is a letter. A parser fed one character at a time that starts over at its
    address takes it as ``5!``: the lagopus sketch on EnviroDIY's library answered ``0M5!``
    (docs/kit.md, sixteenth round), which the a!/aI!/aM! probes never showed."""
    code = "D" if sensor.address.isdigit() else "A"
    return f"{sensor.foreign_address()}{code}{sensor.address}!"


def _answers_anywhere(sensor, sweep) -> HeardProbe | None:
    """Where a change back in the sweep went unanswered (the sensor may never have left its
    address), a! at an address no case gives it, with its control: returned when it was
    answered or not heard, so the answers at each new address show no move (address-change-
    not-applied beside answers-foreign-address, seed 4104: R-4.3-03 PASSed on a! answered
    at 1..9 by a sensor left at '0'). None: no such doubt, or the probe was silent."""
    back = [
        ex
        for ex in sweep.exchanges
        if ex.command is not None
        and ex.command.kind is Kind.CHANGE_ADDRESS
        and ex.command.address != sensor.address
        and not ex.answered
    ]
    if not back:
        return None
    heard = sensor.heard_probe(f"{sensor.foreign_address()}!")
    return heard if heard.probe.answered or not heard.listening else None


@requirements("R-4.0-01")
@pytest.mark.preconditions("listening")
def test_foreign_addresses_are_ignored(sensor, case):
    """Commands for other addresses, each after a break, must draw no reply: a!, aI!, aM!
    at three spare addresses, and one that ends in the DUT's own address."""
    case.expect("silence to a!, aI! and aM! sent to addresses the sensor does not have")
    probes = [
        sensor.heard_probe(f"{other}{code}!")
        for other in spare_addresses(sensor)
        for code in ("", "I", "M")
    ]
    probes.append(sensor.heard_probe(ends_in_own_address(sensor)))
    case.evidence("foreign-address probes, each with its a! control", [p.exchanges for p in probes])
    case.requires("listening", precondition.silence_listening(probes))
    case.add(
        judge.silent_while_listening("R-4.0-01", probes, "the command was for another address")
    )


@requirements("R-4.4.3-01")
@pytest.mark.preconditions("alone")
def test_query_address(sensor, case):
    """?! returns the sensor's address, whatever it is."""
    case.expect(f"'{sensor.address}<CR><LF>'")
    if sensor.shared and not case.requires("alone", precondition.alone(sensor.others, "?!")):
        return
    ex = sensor.once("query", sensor.master.query_address)
    case.evidence("?!", ex)
    case.add(judge.reply_only_address(ex, sensor.address, "R-4.4.3-01", "?!"))


@requirements("R-4.4.3-02")
@pytest.mark.preconditions("listening", "alone")
def test_wildcard_with_other_commands(sensor, case):
    """A sensor may accept ? with other commands; if it answers ?I!, it answers correctly."""
    case.expect("silence, or the same identification as aI!")
    if sensor.shared and not case.requires("alone", precondition.alone(sensor.others, "?I!")):
        return
    heard = sensor.heard_probe("?I!")
    ex = heard.probe
    ident = sensor.exchange("I")
    case.evidence("?I! and its a! control", heard.exchanges)
    deaf = precondition.listening([heard])
    if not ident.answered:
        deaf = precondition.Unmet(
            "listening", "aI! got no reply, so silence to ?I! says nothing", (judge.shown(ident),)
        )
    if not case.requires("listening", None if ex.answered else deaf):
        pass  # its silence to ?I! says nothing
    elif not ex.answered:
        case.add(
            passed(
                "R-4.4.3-02",
                "no reply to ?I! (allowed: ? with other commands is optional); the a! sent "
                "the same way right after it was answered",
                observed=2,  # the silence to ?I! and the answered control that gives it meaning
            )
        )
    elif ex.reply_text == ident.reply_text:
        case.add(passed("R-4.4.3-02", "?I! answered like aI!", observed=2))
    else:
        case.add(
            failed(
                "R-4.4.3-02",
                f"?I! answered '{judge.escape(ex.reply_text)}', unlike "
                f"aI! '{judge.escape(ident.reply_text)}'",
                evidence=judge.cite([ex, ident]),
                observed=2,
            )
        )


@requirements("R-4.3-02")
@pytest.mark.preconditions("none")
def test_factory_address(sensor, case):
    """A sensor as shipped answers at address 0."""
    case.expect("address 0 on a unit fresh from the factory")
    fresh = sensor.declaration.factory_fresh
    if sensor.address == "0":
        own = sensor.exchange("I")
        if own.answered:
            case.add(
                passed("R-4.3-02", f"the sensor is at address 0: {judge.shown(own)}", observed=1)
            )
        else:
            case.add(inconclusive("R-4.3-02", "nothing answered at address 0 (aI!)"))
    elif fresh and (own := sensor.exchange("I")).answered:
        case.add(
            failed(
                "R-4.3-02",
                f"declared fresh from the factory but at address '{sensor.address}'",
                evidence=[judge.cited(own)],
                observed=1,
            )
        )
    else:
        case.add(
            inconclusive(
                "R-4.3-02",
                f"the sensor is at '{sensor.address}'; it may have "
                "been re-addressed (declare factory_fresh = true to judge)",
            )
        )


def _about(ex: Exchange, address: str, sweep: Sweep) -> bool:
    """Whether ``ex`` is the sweep's change to ``address`` or, where the sensor took it and
    answered no poll in a window (``sweep.unanswered``), a poll there: a poll answered only
    late shows the sensor at ``address`` (replies-after-retry + slow-wake: every 3! poll's
    '3<CR><LF>' came 80 ms after its last try, and "refused or lost address(es) 3, ..., 9"
    FAILed R-4.3-03, truth20)."""
    return f"A{address}!" in ex.text or (address in sweep.unanswered and ex.text == f"{address}!")


def _late_refusals(refused: list[str], asked: list[Exchange], sweep: Sweep) -> set[str]:
    """Of ``refused``, the addresses whose change, or poll there, was answered late
    (:func:`~conformance.judges.late_before.answered_late`): its reply came only after the
    reply window (it ran into the retries: replies-after-retry's '1<CR><LF>' to 0A1!), or
    the reply it took may be the command before's, late. Such a change was not shown
    refused, nor an address shown lost: R-7.0-10's deviation. Beside parity-error and
    concurrent-zero, the third try of a 0! (its second try's reply, a bad-parity LF, was
    retried) went unanswered and its '0<CR><LF>' came 80 ms later, in 0A2!'s window: read
    as 0A2!'s answer naming the old address, "refused or lost address(es) 2" FAILed
    R-4.3-03 though the restore found the sensor at '2' (seed 6202, truth22)."""
    return {
        r for r in refused if any(judge.answered_late(ex) for ex in asked if _about(ex, r, sweep))
    }


def _took_unheard(rid: str, found: list[str], asked: list[Exchange]) -> Finding:
    """INCONCLUSIVE for the addresses the sensor took with no reply heard: the restore found
    it there (it answered at its own address only after the move back from each). The
    replies-after-retry sensor beside slow-wake heard each sequence's third 0A1! only, and
    its '1<CR><LF>', 80 ms later, met the tool's next break: "refused or lost address(es)
    1" FAILed R-4.3-03, though 1A0! brought it back (truth20). Whether it answers there
    went unasked."""
    return inconclusive(
        rid,
        f"no reply heard to the change to {', '.join(found)}, but the sensor answered at its "
        "own address only after the move back from there: it took "
        + ("them" if len(found) > 1 else "it")
        + " (unheard: its reply may have met the tool's next break)",
        evidence=judge.cite(asked),
    )


@requirements("R-4.3-03", "R-4.3-04")
@pytest.mark.preconditions("supported", listening=("R-4.3-03", "R-4.3-04"), alone=("R-4.3-03",))
def test_address_range(sensor, case):
    """A sensor with a settable address takes each of 0-9, and refuses a non-address."""
    case.expect(
        "aAb! accepted for b = 0..9 (restored afterwards); a character that is not an "
        "address is refused"
    )
    settable = sensor.address_change_supported()
    if not case.requires(
        "supported",
        precondition.served(settable, "the sensor's address is not software-settable"),
    ):
        return
    # on a shared bus the sweep would move the sensor onto another's address
    in_the_way = sensor.others & set("0123456789")
    alone = not in_the_way or case.requires(
        "alone", precondition.alone(in_the_way, "the address sweep 0-9")
    )
    sweep = sensor.address_sweep("0123456789" if alone else "")
    case.evidence("address sweep", sweep.exchanges)
    refused = sweep.refused
    # taken, then silent to a! at the new address: lost only if the sensor answers a! at all
    polls = [ex for ex in sweep.exchanges if ex.command and ex.command.kind is Kind.ACKNOWLEDGE]
    unheard = None
    if refused and set(refused) <= set(sweep.unanswered):
        unheard = sensor.acknowledges(polls)
    if not alone:
        pass  # R-4.3-03 is INCONCLUSIVE: the sweep was not made
    elif not case.requires("listening", unheard, only=("R-4.3-03",)):
        pass  # "lost" rests on silence to a!, which this sensor never answers
    elif refused:
        asked = [ex for ex in sweep.exchanges if any(_about(ex, r, sweep) for r in refused)]
        late = _late_refusals(refused, asked, sweep)
        found = [r for r in refused if r in sweep.found_at and r not in late]
        if found and set(refused) <= late | set(found):
            case.add(_took_unheard("R-4.3-03", found, asked))
        elif late == set(refused):
            case.add(
                judge.late_among(
                    "R-4.3-03", asked, "refused or lost address(es) " + ", ".join(refused)
                )
            )
        else:
            case.add(
                failed(
                    "R-4.3-03",
                    "refused or lost address(es) "
                    + ", ".join(r for r in refused if r not in late and r not in found),
                    evidence=judge.cite(asked or sweep.exchanges),
                    observed=len(sweep.exchanges),
                )
            )
    elif (anywhere := _answers_anywhere(sensor, sweep)) is not None:
        case.evidence("a! at an address it never had", anywhere.exchanges)
        case.add(
            inconclusive(
                "R-4.3-03",
                "answered at every address 0-9, but a change back went unanswered and "
                + (
                    f"'{anywhere.probe.text}' was answered too, at an address it never had"
                    if anywhere.probe.answered
                    else "no control was heard after a! at an address it never had"
                )
                + f": its answers do not show it moved; {sweep.restore_note}",
                evidence=judge.cite(anywhere.exchanges),
                observed=len(sweep.exchanges) + len(anywhere.exchanges),
            )
        )
    else:
        shown = "answered there"
        if sweep.heard:
            # it answers no a!: ?! named each address and its move back from there was answered
            shown = (
                f"answered there ({', '.join(sweep.heard)}: ?! named the address and the "
                "move back from it was answered; the sensor answers no a! anywhere)"
            )
        case.add(
            passed(
                "R-4.3-03",
                f"accepted every address 0-9 and {shown}; {sweep.restore_note}",
                observed=len(sweep.exchanges),
            )
        )
    bad = sensor.try_invalid_address("$")
    case.evidence("aA$!", bad.exchanges)
    deaf = None
    if alone and not any(ex.answered for ex in sweep.exchanges):
        deaf = precondition.Unmet(
            "listening",
            "it answered none of the address changes to 0-9 either, so refusing '$' shows nothing",
        )
    elif not bad.accepted and not bad.listening:
        if bad.control is None:  # no marking made it answer a one-shot a!: none was sent
            why = "no one-shot a! after a break was answered, and no control went like aA$!"
        elif bad.recheck is not None and precondition.shows_listening(bad.control):
            why = (
                "the a! sent like aA$! (one break, then once) was answered, the same a! after "
                "the next break not: the sensor wakes differently from break to break"
            )
        else:
            why = "the a! sent like aA$! (one break, then once) got no reply"
        deaf = precondition.Unmet(
            "listening",
            f"{why}, so the silence to aA$! shows nothing",
            tuple(judge.cite([ex for ex in (bad.control, bad.recheck) if ex is not None])),
        )
    if not case.requires("listening", deaf, only=("R-4.3-04",)):
        pass  # refusing '$' shows nothing from a sensor not shown listening
    elif bad.accepted:
        case.add(
            failed(
                "R-4.3-04",
                "took '$' as its address"
                + (" (its reply '$<CR><LF>' came late, after its window)" if bad.late else "")
                + " (decision A17: only 0-9, A-Z, a-z)",
                decision="A17",
                evidence=judge.cite(bad.exchanges),
                observed=len(bad.exchanges),
            )
        )
    else:
        case.add(
            passed(
                "R-4.3-04",
                f"refused '$' as an address (and answered the a! sent the same way after it, and "
                "again after the next break); "
                f"{len(ADDRESS_CHARS)} characters are addresses",
                decision="A17",
                observed=len(bad.exchanges),
            )
        )
