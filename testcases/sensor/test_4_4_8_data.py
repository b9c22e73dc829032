"""Section 4.4.8: the send-data command aD0..aD9!, value format, limits and grouping."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import measurements as judge
from conformance.judges.exchanges import cite, late_among, shown
from conformance.judges.support import first_filled
from conformance.protocol.commands import C_FAMILY, M_FAMILY
from conformance.protocol.responses import (
    parse_data_reply_for,
    parse_measurement_reply_for,
    split_line,
)
from conformance.verdicts import failed, inconclusive, passed

requirements = pytest.mark.requirements
ASCII_FAMILIES = M_FAMILY + C_FAMILY


@requirements("R-4.4.8-01", "R-4.4.8-02", "R-4.4-05")
@pytest.mark.preconditions(buffered=("R-4.4.8-02", "R-4.4-05"), none=("R-4.4.8-01",))
def test_data_replies(sensor, case):
    """D replies are address + values [+ CRC] + CR LF; values are well formed; the values
    part stays within 35 characters after M-type commands and 75 after C-type ones."""
    case.expect(
        "'a<values>[<CRC>]<CR><LF>'; each value sign + 1..7 digits + at most one '.', "
        "at most 9 characters (decision A13 warns on odd spellings)"
    )
    ms = sensor.defined(ASCII_FAMILIES)
    case.evidence("every defined measurement's D replies", ms)
    case.requires("buffered", precondition.buffered_any(ms))
    case.extend(judge.judge(ms, case.requirements, sensor.version))
    case.extend(judge.unread_data(sensor.family(ASCII_FAMILIES), case.requirements))


@requirements("R-4.4.8-03", "R-4.4.8-04")
@pytest.mark.preconditions("supported")
def test_announced_values_delivered(sensor, case):
    """The D replies add up to the announced count; D0 is not empty when values are due."""
    case.expect("D0, D1, ... return exactly n (or nn, nnn after aHA!) values in all")
    ms = sensor.defined(ASCII_FAMILIES + ("HA",))
    case.evidence("every defined measurement", ms)
    case.requires(
        "supported", precondition.shown_supported(bool(ms), "no measurement announced values")
    )
    case.extend(judge.judge(ms, case.requirements, sensor.version))
    case.extend(judge.unread_data(sensor.family(ASCII_FAMILIES + ("HA",)), case.requirements))
    # a start answered only after its reply window and not read as 'atttn' (its count
    # unknown) is a measurement the rule could not follow: the others' PASS is not the whole
    # sensor's (replies-after-retry + high-volume-two-digit-count, seed 4900: 0HA!'s late
    # reply unread, R-4.4.8-03/04 PASSed on the eight others while 0HA! breaks them alone)
    unread = [m.start for m in sensor.family(ASCII_FAMILIES + ("HA",)) if m.count is None]
    for rid in case.requirements:
        if late := late_among(rid, unread, "not every start's count was read"):
            case.add(late)


@requirements("R-4.4.8.3-01", "R-4.4.8.3-02", "R-4.4.8.3-03")
@pytest.mark.preconditions("buffered")
def test_value_grouping(sensor, case):
    """No value split over two replies; groups in order from D0; replies filled (SHOULD)."""
    case.expect(
        "every D reply starts with a sign; no empty Dk before a Dk+1 with values; a "
        "reply leaves no room for the next reply's first value"
    )
    ms = sensor.defined(ASCII_FAMILIES)
    case.evidence("every defined measurement", ms)
    case.requires("buffered", precondition.buffered_any(ms))
    case.extend(judge.judge(ms, case.requirements, sensor.version))
    case.extend(judge.unread_data(sensor.family(ASCII_FAMILIES), case.requirements))


@requirements("R-4.4.8-03")
@pytest.mark.preconditions("buffered")
def test_undefined_group_leaves_no_old_values(sensor, case):
    """After 'a0000' for an undefined aMn!, aD0! returns no values: none were announced, and
    the previous measurement's must not come back as this one's."""
    case.expect("a measurement with values, then aMn! -> 'a0000', then aD0! -> 'a<CR><LF>'")
    # 'a0000': no values and nothing running. A group that announces no values but a ttt
    # (aM! of a sensor that counts 0) is measuring: a D0 sent at once aborts it, and what a
    # sensor returns after an abort is R-4.4.5.1-02's to judge (a sensor that keeps the old
    # data there FAILed this rule instead, pinned on the wrong deviation)
    undefined = next(
        (m for m in sensor.family(M_FAMILY) if m.start.answered and m.count == 0 and not m.ttt),
        None,
    )
    filled = next((m for m in sensor.defined(("M", "V", *M_FAMILY)) if m.value_count), None)
    if undefined is None:
        # "every one is defined" only where each was answered: a sensor silent to aMn! (the
        # twenty-ninth outside round's mock sensor) defines none of them
        groups = sensor.family(M_FAMILY)
        answered = [m for m in groups if m.start.answered]
        why = (
            "every one is defined"
            if len(answered) == len(groups)
            else "those answered are defined"
            if answered
            else "none was answered"
        )
        case.not_applicable(f"no aMn! group answers 'a0000' ({why})")
        return
    if not case.requires("buffered", precondition.buffered(filled, "measurement")):
        return
    code = undefined.command.text()[1:-1]
    before = sensor.fresh_measurement(filled.command.text()[1:-1])
    start = sensor.fresh_exchange(code)
    # the D commands up to the one that gave `before` its first values: a sensor whose
    # groups start at D1 answers D0 empty whatever it keeps, so an empty D0 alone showed
    # nothing (groups-start-at-d1 + undefined-group-keeps-data PASSed, seed 4064)
    ds: list = []
    for i in range(first_filled(before) + 1):
        ds.append(sensor.fresh_exchange(f"D{i}"))
        if not ds[-1].answered or _values(ds[-1], start.command, sensor.address):
            break
    case.evidence(f"{filled.command}, then {code} and D0..", [before, start, *ds])
    announced = parse_measurement_reply_for(split_line(start.reply_text)[0], start.command)
    asked = "; ".join(shown(d) for d in ds)
    returned = next((d for d in ds if _values(d, start.command, sensor.address)), None)
    if not (
        before.value_count
        and start.answered
        and announced.count == 0
        and not announced.ttt
        and all(d.answered for d in ds)
    ):
        case.add(
            inconclusive(
                "R-4.4.8-03",
                f"needs values first, then 'a0000' and answered D replies: {shown(start)}; "
                + asked,
            )
        )
    elif returned is not None:
        case.add(
            failed(
                "R-4.4.8-03",
                f"{shown(start)} announced no values, yet {shown(returned)} returned some "
                f"(the previous {filled.command}'s?)",
                evidence=cite([start, returned]),
                observed=1,
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.8-03",
                f"{shown(start)} then {asked}: no values",
                observed=3,  # the measurement with values, the empty announcement, its D's
            )
        )


def _values(ex, command, address: str) -> list[str]:
    """The values of a D reply to a measurement started by ``command``."""
    body, _ = split_line(ex.reply_text)
    return parse_data_reply_for(body, command, expected_address=address).values
