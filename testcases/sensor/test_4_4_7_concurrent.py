"""Section 4.4.7: concurrent measurements (aC!, aCC!, aC1..9!, aCC1..9!)."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as judge
from conformance.judges.stalled import unless_stalled
from conformance.judges.support import (
    empty_data_reply,
    serves_measurement,
    text_instead_of_start,
)
from conformance.protocol.commands import C_FAMILY
from conformance.protocol.responses import split_line
from conformance.verdicts import failed, inconclusive, passed, warned

requirements = pytest.mark.requirements


@requirements("R-4.4.7-01", "R-4.4.7-02", "R-4.4.7-03")
@pytest.mark.preconditions("none")
def test_concurrent_reply(sensor, case):
    """Concurrent commands answer atttnn; aC! measures for real; nn fits the claimed version."""
    case.expect("'atttnn<CR><LF>'; aC! is not 'a00000'; nn <= 20 under v1.3 (decision A2 warns)")
    ms = sensor.family(C_FAMILY)
    sensor.check_declared_counts(C_FAMILY)
    case.evidence("C-family replies", [m.start for m in ms])
    case.extend(judge.judge(ms, case.requirements, sensor.version))


@pytest.mark.needs("unsolicited")
@requirements("R-4.4.7-04")
@pytest.mark.preconditions("supported")
def test_quiet_during_concurrent(sensor, case):
    """Between its atttnn reply and the aD0! the sensor sends nothing."""
    case.expect("no character from the sensor while the concurrent measurement runs")
    ms = [m for m in sensor.family(C_FAMILY) if m.ttt]
    case.evidence("concurrent measurements with ttt > 0", ms)
    if not case.requires(
        "supported", precondition.served(bool(ms), "no concurrent measurement announced ttt > 0")
    ):
        return
    case.extend(judge.judge(ms, case.requirements, sensor.version))


@requirements("R-4.4.7-08")
@pytest.mark.preconditions("none")
def test_concurrent_supported(sensor, case):
    """A sensor claiming v1.2 or later (every ll this tool knows) answers aC!."""
    case.expect("a reply to aC! (its format is judged by R-4.4.7-01)")
    m = sensor.measurement("C")
    case.evidence("aC!", m.start)
    # a malformed reply still answers aC! (R-4.4.7-01 judges its form); a00000 does not,
    # nor a malformed one whose every reading is zero values (a000000: a 3-digit zero count),
    # nor text with no digit (aUNKN)
    zero = m.start.answered and (m.count == 0 or (m.count is None and _all_zero(m.start)))
    text = text_instead_of_start(m)  # 'aUNKN': the sensor says it does not know aC!
    tried = (
        not zero and not text and (serves_measurement(m) or (m.start.answered and m.count is None))
    )
    if tried and m.start.reply_text[:1] == sensor.address:
        case.add(
            passed("R-4.4.7-08", f"aC! answered '{xjudge.escape(m.start.reply_text)}'", observed=1)
        )
    else:
        seen = xjudge.shown(m.start)
        case.add(
            failed(
                "R-4.4.7-08",
                f"aC! answered {seen}: zero values, no measurement started"
                if zero
                else f"aC! not supported: {seen}",
                evidence=[xjudge.cited(m.start)],
                observed=1,
            )
        )


def _all_zero(start) -> bool:
    """A reply whose characters after the address, ttt and at least two count digits, are
    all '0': zero values however its malformed count is read (a 3-digit '000' beside
    concurrent-zero was taken for a started measurement)."""
    body = start.reply_text.removesuffix("\r\n")[1:]
    return len(body) >= 5 and set(body) == {"0"}


def _running_concurrent(sensor):
    """A defined concurrent measurement with ttt >= 1, to be disturbed while it runs."""
    return next((m for m in sensor.family(("C", "CC", *C_FAMILY[2:])) if m.ttt and m.count), None)


@pytest.mark.needs("break")
@requirements("R-4.4.7-05")
@pytest.mark.preconditions("supported", "buffered", "listening")
def test_concurrent_survives_break_and_other_traffic(sensor, case):
    """A break and a command to another address do not abort a running concurrent
    measurement (decision A4)."""
    case.expect("all announced values delivered after a break and a foreign-address command")
    target = _running_concurrent(sensor)
    if not case.requires(
        "supported",
        precondition.served(target is not None, "no concurrent measurement with ttt > 0"),
    ):
        return
    if not case.requires("buffered", precondition.buffered(target, "concurrent measurement")):
        return
    code = target.command.text()[1:-1]
    other = sensor.foreign_address()
    m, poke = sensor.disturbed_measurement(target.command, f"{other}I!")
    case.evidence(f"{code} with a break and {other}I! while it ran", [m, poke])
    unheard = precondition.heard_one_shot(sensor.hearing_marking(), f"{other}I!")
    if m.value_count >= target.value_count and not case.requires("listening", unheard):
        pass  # delivering all values shows nothing then
    elif m.value_count >= target.value_count:
        case.add(
            passed(
                "R-4.4.7-05",
                f"{code} delivered {m.value_count} values after a break "
                f"and {other}I!, as many as undisturbed",
                decision="A4",
                observed=m.value_count,  # none delivered undisturbed either: nothing to judge
            )
        )
    elif late := xjudge.late_among(
        "R-4.4.7-05",
        [m.start, *m.data],
        f"{code} delivered {m.value_count} values after a break and {other}I!, "
        f"{target.value_count} undisturbed",
    ):
        case.add(late)
    else:
        fewer = failed(
            "R-4.4.7-05",
            f"{code} delivered {m.value_count} values after a break "
            f"and {other}I!, {target.value_count} undisturbed (aborted?)",
            decision="A4",
            evidence=xjudge.cite([m.start, poke, *m.data]),
            observed=2,  # the undisturbed measurement and the disturbed one
        )
        # values counted over its reads together: one the tool's host stalled over may have
        # been cut, its rest a late burst (a clean emulator behind RFC 2217, the tool
        # paused 80-200 ms every 0.3-0.9 s: "C delivered 18 values ..., 20 undisturbed",
        # truth30)
        case.add(unless_stalled(fewer, [m.start, *m.data], together=True))


@pytest.mark.needs("break")
@requirements("R-4.4.7.1-01", "R-4.4.7.1-02")
@pytest.mark.preconditions("supported", "pending")
def test_own_command_aborts_concurrent(sensor, case):
    """A valid command to the sensor itself aborts a running concurrent measurement; its D
    replies are then empty."""
    case.expect("after aI! during the measurement, aD0! answers 'a[<CRC>]<CR><LF>'")
    target = next(
        (m for m in sensor.family(("CC", "C", *C_FAMILY[2:])) if m.ttt and m.value_count), None
    )
    if not case.requires(
        "supported",
        precondition.served(
            target is not None, "no concurrent measurement with ttt > 0 and values"
        ),
    ):
        return
    code = target.command.text()[1:-1]
    sensor.fill_data_buffer(code)  # data kept from before the abort must show as values
    # an empty D0 after the abort shows the abort emptied the buffer only where the buffer
    # keeps values through what comes before the abort (values read to the end, standby, a
    # break: abort-keeps-old-data beside buffer-cleared-after-read PASSed here as for
    # R-4.4.5.1-02), so those steps first: one D read, not another aC! after the abort
    kept = sensor.values_after_standby(target)
    case.evidence("standby, break, D0 before the abort", kept)
    m, poke = sensor.disturbed_measurement(target.command, f"{sensor.address}I!")
    case.evidence(f"{code} interrupted by {sensor.address}I!", [m, poke])
    if poke.attempts and poke.attempts[0].command_events:  # an abort needs a running one
        first = poke.attempts[0].command_events[0]
        case.requires("pending", precondition.pending(m.start, m.ttt or 0, [], first, poke.text))
    d0 = m.data[0] if m.data else None
    if not poke.answered:
        case.add(
            inconclusive(
                "R-4.4.7.1-01",
                f"{sensor.address}I! was not answered; the interruption cannot be judged",
            )
        )
        case.not_applicable("no interruption happened", ["R-4.4.7.1-02"])
        return
    if d0 is None or not d0.answered:
        case.add(inconclusive("R-4.4.7.1-01", "aD0! after the interruption got no reply"))
        case.not_applicable("no D0 reply to judge", ["R-4.4.7.1-02"])
        return
    body, _ = split_line(d0.reply_text)
    if m.value_count:  # not aborted, or aborted with the old data kept: not separable
        seen = xjudge.shown(d0)
        case.add(
            warned(
                "R-4.4.7.1-01",
                f"{code} still delivered values after {sensor.address}I!: {seen}",
                decision="A3",
                evidence=xjudge.cite([m.start, poke, d0]),
                observed=1,
            )
        )
        case.add(
            warned(
                "R-4.4.7.1-02",
                f"D0 after the interruption should be empty: {seen} "
                "(the sensor either did not abort or kept its data)",
                evidence=xjudge.cite([poke, d0]),
                observed=1,
            )
        )
        return
    if woke := [a.break_event for a in poke.attempts if a.break_event is not None]:
        # a break of the tool's own before a try of aI! (a retry of an unaccepted reply, or a
        # sensor that needed waking): an empty D0 may be that break's abort, not the
        # command's (seed 5700: break-aborts-concurrent + concurrent-not-aborted +
        # ident-bad-version PASSed here)
        why = (
            f"{code} gave no values after {sensor.address}I!, but {len(woke)} of its tries "
            f"went after a break of the tool's own (first at {woke[0].start:.3f} s): the "
            "abort may be the break's"
        )
        case.add(inconclusive("R-4.4.7.1-01", why, evidence=xjudge.cite([m.start, poke, d0])))
        case.add(inconclusive("R-4.4.7.1-02", why))
        return
    case.add(
        passed(
            "R-4.4.7.1-01",
            f"{code} aborted by {sensor.address}I!",
            decision="A3",
            observed=2,  # the answered aI! and the empty D0 after it
        )
    )
    if empty_data_reply(d0) and not any(d.answered and not empty_data_reply(d) for d in kept):
        case.add(
            inconclusive(
                "R-4.4.7.1-02",
                f"no values after the abort: {xjudge.shown(d0)}, but the buffer was not shown"
                " to hold values up to the abort: before it, standby, a break and D0 gave"
                " none either: " + "; ".join(xjudge.shown(d) for d in kept),
                observed=1 + len(kept),
            )
        )
    elif empty_data_reply(d0):
        case.add(
            passed(
                "R-4.4.7.1-02",
                f"no values after the abort: {xjudge.shown(d0)} (its CRC is judged by R-4.4.12-05)",
                observed=1,
            )
        )
    else:
        case.add(
            warned(
                "R-4.4.7.1-02",
                f"after the abort expected 'a[<CRC>]<CR><LF>', got {xjudge.shown(d0)}",
                evidence=xjudge.cite([poke, d0]),
                observed=1,
            )
        )
