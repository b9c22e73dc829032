"""Sections 4.4.5-4.4.6: aM!-type measurements, service requests, aborts, the data buffer."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import measurements as judge
from conformance.judges.exchanges import (
    answered_late,
    cite,
    cited,
    heard,
    late_among,
    late_only,
    shown,
)
from conformance.judges.retention import retained
from conformance.judges.support import announced_ttt, empty_data_reply, first_filled
from conformance.judges.wake_heard import first_sequence_unheard, unheard
from conformance.judges.wire import runs
from conformance.protocol.commands import C_FAMILY, HV_FAMILY, M_FAMILY
from conformance.protocol.responses import is_service_request, split_line
from conformance.transcript import decode_7e1, escape
from conformance.verdicts import failed, inconclusive, passed, warned

requirements = pytest.mark.requirements
SR_FAMILY = M_FAMILY  # decision A5: the whole M family and V raise service requests


@requirements("R-4.4.5-01", "R-4.4.5-02")
@pytest.mark.preconditions("none")
def test_measurement_reply(sensor, case):
    """aM!, aMC!, aM1..9!, aMC1..9!, aV! answer atttn; a defined measurement has n of 1..9."""
    case.expect(
        "'atttn<CR><LF>' with 3 digits of seconds and 1 digit of count; n >= 1 for "
        "aM!/aMC!/aV! (decision A1: 0 only for an undefined group)"
    )
    ms = sensor.family(SR_FAMILY)
    case.evidence("M-family replies", [m.start for m in ms])
    case.extend(judge.judge(ms, case.requirements, sensor.version))
    sensor.check_declared_counts(SR_FAMILY)
    for m in ms:  # a group the declaration defines must not announce zero values
        code = m.command.text()[1:-1]
        if sensor.declared_count(code) and m.count == 0:
            case.add(
                failed(
                    "R-4.4.5-02",
                    f"{code} is declared with {sensor.declared_count(code)} "
                    "values but announced none",
                    decision="A1",
                    evidence=[cited(m.start)],
                    observed=1,
                )
            )


@pytest.mark.needs("unsolicited")
@requirements("R-4.4.6-01", "R-4.4.6-02", "R-4.4.6-04", "R-4.4.5-08", "R-4.4.5-09")
@pytest.mark.preconditions("supported")
def test_service_request(sensor, case):
    """With ttt > 0 the sensor sends 'a<CR><LF>' when data are ready, before ttt runs out, and
    nothing else meanwhile."""
    case.expect(
        "exactly 'a<CR><LF>', complete within ttt s of the reply (decision A6), no "
        "other character before it; ttt not much longer than needed"
    )
    ms = [m for m in sensor.family(SR_FAMILY) if m.ttt]
    case.evidence("measurements with ttt > 0", ms)
    if not case.requires(
        "supported", precondition.served(bool(ms), "no M-family measurement announced ttt > 0")
    ):
        return
    case.extend(judge.judge(ms, case.requirements, sensor.version))


@pytest.mark.needs("unsolicited")
@requirements("R-4.4.6-03", "R-4.4.5-03")
@pytest.mark.preconditions("supported")
def test_ttt_zero(sensor, case):
    """With ttt = 000 there is no service request and aD0! returns the data at once."""
    case.expect("silence after 'a000n', then values from an immediate aD0!")
    zero = [
        code
        for code in SR_FAMILY
        if sensor.measurement(code).ttt == 0 and sensor.measurement(code).count
    ]
    if not case.requires(
        "supported",
        precondition.served(bool(zero), "no measurement announced ttt = 000 with values"),
    ):
        return
    code = zero[0]
    start = sensor.fresh_exchange(code)
    grace = sensor.master.policy.late_sr_grace
    quiet = sensor.listen_until(_reply_end(start) + grace)  # ttt = 0: the grace alone
    d0 = sensor.fresh_exchange("D0")
    case.evidence(f"{code} with ttt 000, {grace:.1f} s of listening, D0", [start, quiet, d0])
    if late := answered_late(start):
        # no 'a000n' taken this time: what came after may be its late reply, not a request
        # ('00002' 80 ms after 0M1! FAILed "sent '00002' after '' announced ttt = 000",
        # replies-after-retry beside slow-wake, fast-baud and others, truth15)
        case.add(
            inconclusive(
                "R-4.4.6-03",
                f"{code} again: {late} (R-7.0-10 judges its timing): no ttt = 000 announced"
                " to hold what followed to",
                evidence=[cited(start)],
            )
        )
    elif not start.answered:
        # no start reply, so no ttt = 000 to hold what followed to: replies-after-retry +
        # slow-wake's 0M1! met its tries only after each break's 110 ms wake-up, and its
        # '00002' came 80 ms after the last: "sent '00002' after '' announced ttt = 000"
        # FAILed (truth18)
        then = f"; then '{escape(decode_7e1(quiet))}'" if quiet else ""
        case.add(
            inconclusive(
                "R-4.4.6-03",
                f"no reply to {escape(start.text)} this time{then}: no ttt = 000 announced to hold "
                "what followed to",
                evidence=[cited(start)] + ([heard(quiet, "then, unasked")] if quiet else []),
            )
        )
    elif announced_ttt(start) != 0:
        # this time's reply announced no ttt = 000 (a service request's '0<CR><LF>' taken for
        # 0M1!'s reply, replies-after-retry beside service-request-after-ttt-zero: "no service
        # request in 0.5 s after 0M1! -> '0<CR><LF>'" PASSed, truth19): nothing to hold what
        # followed, or its silence, to
        case.add(
            inconclusive(
                "R-4.4.6-03",
                f"{shown(start)} this time, no ttt = 000 announced to hold what followed to",
                evidence=[cited(start)] + ([heard(quiet, "then, unasked")] if quiet else []),
            )
        )
    elif quiet:
        case.add(
            failed(
                "R-4.4.6-03",
                f"sent '{escape(decode_7e1(quiet))}' after "
                f"'{escape(start.reply_text)}' announced ttt = 000",
                evidence=[cited(start), heard(quiet, "then, unasked")],
                observed=1,
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.6-03",
                f"no service request in {grace:.1f} s after {shown(start)}",
                observed=1,
            )
        )
    body, _ = split_line(d0.reply_text)
    late = late_only("R-4.4.5-03", d0, "aD0! right after ttt = 000")
    if late is not None:
        case.add(late)
    elif not start.answered and not (d0.answered and len(body) > 1 and body[1] in "+-"):
        # no measurement shown started this time: an empty or unanswered aD0! after it
        # says nothing of data ready at once (the same 0M1!'s 0D0!, met only after each
        # break's wake-up, FAILed "gave no values: 0D0! -> '(silence)'", truth18)
        case.add(
            inconclusive(
                "R-4.4.5-03",
                f"aD0! after {escape(start.text)}, which drew no reply this time: {shown(d0)}",
                evidence=[cited(start), cited(d0)],
            )
        )
    elif d0.answered and len(body) > 1 and body[1] in "+-":
        case.add(passed("R-4.4.5-03", f"data ready at once: {shown(d0)}", observed=1))
    else:
        case.add(
            failed(
                "R-4.4.5-03",
                f"aD0! right after ttt = 000 gave no values: {shown(d0)}",
                evidence=[cited(start), cited(d0)],
                observed=1,
            )
        )


@pytest.mark.needs("unsolicited")
@requirements("R-4.4.6-05")
@pytest.mark.preconditions("supported")
def test_no_service_request_after_concurrent(sensor, case):
    """C, CC, Cn, CCn, HA and HB are never followed by a service request."""
    case.expect("no 'a<CR><LF>' between the atttnn/atttnnn reply and the D command")
    ms = [m for m in sensor.family(C_FAMILY + HV_FAMILY) if m.ttt]
    case.evidence("concurrent measurements", ms)
    if not case.requires(
        "supported", precondition.served(bool(ms), "no concurrent measurement announced ttt > 0")
    ):
        return
    case.extend(judge.judge(ms, case.requirements, sensor.version))


@pytest.mark.needs("break")
@requirements("R-4.4.5-10")
@pytest.mark.preconditions("buffered")
def test_data_retained(sensor, case):
    """Data stay readable, unchanged, across a break, standby and non-measuring commands."""
    case.expect("the same D replies before and after: break, >100 ms idle, aI!, a!, break")
    m = next((m for m in sensor.family(("M", "MC", "V", *M_FAMILY)) if m.value_count), None)
    if m is None:
        # (seed 4197) aM!'s reply gave no count (a two-digit ttt): a concurrent measurement's
        # values are under the rule as well, and only this case sends the aRn! that
        # continuous-overwrites-data empties the buffer at; the exploration's repeated D0
        # checks repeated reads only. Sent only where no M-type measurement gave values.
        m = next((m for m in sensor.family(("C", "CC")) if m.value_count), None)
    if not case.requires("buffered", precondition.buffered(m, "M-type or concurrent measurement")):
        return
    fresh = sensor.fresh_measurement(m.command.text()[1:-1])
    sensor.to_standby()  # standby
    sensor.master.send_break()
    pokes = [sensor.fresh_exchange(code) for code in ("I", "", "R0", "RC0")]
    sensor.to_standby()
    again = [sensor.fresh_exchange(ex.text[1:-1]) for ex in fresh.data]
    case.evidence(
        "measurement, then break/standby/aI!/a!/aR0!/aRC0!, then the D commands again",
        [fresh, *pokes, *again],
    )
    case.add(retained(fresh.data, again))


@pytest.mark.needs("break", "unsolicited")
@requirements("R-4.4.5.1-01", "R-4.4.5.1-02", "R-4.4.5.1-03", "R-4.4.5-08")
@pytest.mark.preconditions("pending", aborted=("R-4.4.5.1-02", "R-4.4.5.1-03"))
def test_break_aborts_measurement(sensor, case):
    """A break before the service request aborts an M measurement; D0 then has no values and
    the sensor takes a new measurement normally."""
    case.expect(
        "no service request after the break; aD0! answers 'a[<CRC>]<CR><LF>'; a new aM! works"
    )
    candidates = [m for m in sensor.family(("M", "MC", *M_FAMILY[2:])) if m.ttt and m.count]
    if not candidates:
        case.not_applicable("no M-type measurement with ttt > 0 to abort")
        return
    target = candidates[0]
    code = target.command.text()[1:-1]
    sensor.fill_data_buffer(code)  # data kept from before the abort must show as values
    # (seed 4227) where it delivered none (d0-empty), an empty D0 after the abort is what a
    # sensor that kept its old data would give too: no evidence for R-4.4.5.1-02
    filled = bool(target.value_count)
    start = sensor.fresh_exchange(code)
    before = sensor.listen(min(0.05, target.ttt / 10))
    brk = sensor.master.send_break()
    # as long as an undisturbed measurement's service request could come late (R-4.4.6-04:
    # within ttt of its reply, and the engine's grace past that): from that reply, not from
    # the break a break, a read's end and a turnaround later (issue 22)
    grace = sensor.master.policy.late_sr_grace
    waited = sensor.listen_until(_reply_end(start) + target.ttt + grace)
    d0 = sensor.fresh_exchange("D0", crc=target.command.crc)
    # and on to the D command that gave the measurement its first values: where its groups
    # start at D1, D0 is empty whatever the abort left (abort-keeps-old-data beside
    # groups-start-at-d1 PASSed on D0 alone, seed 4066)
    ds = [d0]
    while len(ds) <= first_filled(target) and ds[-1].answered and empty_data_reply(ds[-1]):
        ds.append(sensor.fresh_exchange(f"D{len(ds)}", crc=target.command.crc))
    start2 = sensor.fresh_exchange(code)  # abort again, and this time start anew after it
    before2 = sensor.listen(min(0.05, target.ttt / 10))
    brk2 = sensor.master.send_break()
    again = sensor.measure_as_sent(target.command)  # within 87 ms: no second break
    full = next((d for d in ds if not (d.answered and empty_data_reply(d))), None)
    # an empty D0 shows the abort emptied the buffer only where the buffer held values up
    # to it: a sensor that empties it once its pages were read, at the break after that or
    # in standby gives the same empty D0 whatever the abort does (abort-keeps-old-data
    # beside buffer-cleared-after-read, -by-break, data-lost-after-standby). So the same
    # steps without an abort: read to the end, standby, a break, D0 again
    kept = sensor.values_after_standby(target) if full is None and filled else []
    case.evidence(
        f"{code}, break, wait past ttt, D0; then {code}, break and {code} at once",
        [start, before, [brk], waited, *ds, start2, before2, [brk2], again, *kept],
    )
    # nothing can be aborted that had already finished (issue 18)
    case.requires(
        "pending",
        precondition.pending(start, target.ttt, before, brk)
        or precondition.pending(start2, target.ttt, before2, brk2),
    )
    sent_runs = runs(waited)
    sent = [decode_7e1(r) for r in sent_runs]
    text_of = dict(zip(sent, sent_runs, strict=True))  # evidence: the events of a text
    # a service request is exactly a<CR><LF> (R-4.4.6-01); other text after the break is
    # the sensor talking unasked, not a measurement carrying on
    srs = [t for t in sent if is_service_request(t.removesuffix("\r\n"), sensor.address)]
    # a line the undisturbed measurement sends in its wait too is that measurement carrying
    # on (its own malformed request, '0SR'), judged there, not talk the break set off
    # (break-does-not-abort-measure + service-request-extra-chars, seed 4093)
    usual = {decode_7e1(r) for r in runs(target.waited_events)}
    unasked = [t for t in sent if t not in srs and t not in usual]
    if unasked:
        case.add(
            failed(
                "R-4.4.5-08",
                f"after the break aborted {code} the sensor sent "
                + ", ".join(f"'{escape(t)}'" for t in unasked)
                + " unasked",
                evidence=[f"'{escape(t)}'" for t in unasked],
                observed=len(unasked),
            )
        )
    else:
        case.not_applicable("nothing arrived unasked after the break", ["R-4.4.5-08"])
    abort = precondition.aborted(target, [text_of[t] for t in srs])
    if target.service_request_end is None:
        case.add(abort.finding("R-4.4.5.1-01"))
    elif srs:
        case.add(
            failed(
                "R-4.4.5.1-01",
                "a service request arrived after the break: the measurement was not aborted",
                evidence=[
                    cited(start),
                    f"t={brk.start:.4f} s: break",
                    heard(text_of[srs[0]], "then"),
                ],
                observed=2,  # the undisturbed service request and the one after the break
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.5.1-01",
                f"no service request after the break, up to {target.ttt + grace:.1f} s after "
                f"{code}'s reply (undisturbed, {code} raised one)",
                observed=2,  # the undisturbed service request and the silence after the break
            )
        )
    if not case.requires("aborted", abort):
        return
    if full is None and not filled:
        case.add(
            inconclusive(
                "R-4.4.5.1-02",
                f"D0 after the abort holds no values, but {code} delivered none before it"
                " either: data kept across the abort would look the same: "
                + "; ".join(shown(d) for d in ds),
                decision="A3",
                observed=len(ds),
            )
        )
    elif full is None and not any(d.answered and not empty_data_reply(d) for d in kept):
        case.add(
            inconclusive(
                "R-4.4.5.1-02",
                "D0 after the abort holds no values, but the buffer was not shown to hold"
                f" values up to the abort: after {code}'s values were read to the end,"
                " standby, a break and D0 gave none either, with no abort: "
                + "; ".join(shown(d) for d in (*ds, *kept)),
                decision="A3",
                observed=len(ds) + len(kept),
            )
        )
    elif full is None:  # its address and CRC are judged by their own rules
        case.add(
            passed(
                "R-4.4.5.1-02",
                "D0 after the abort holds no values: " + "; ".join(shown(d) for d in ds),
                decision="A3",
                observed=len(ds),
            )
        )
    elif late := late_only("R-4.4.5.1-02", full, "D0 after the abort should hold no values"):
        case.add(late)  # its values (or none) came after the window, cut by the retries
    else:
        case.add(
            warned(
                "R-4.4.5.1-02",
                f"D0 after the abort should hold no values: {shown(full)}",
                decision="A3",
                evidence=[f"t={brk.start:.4f} s: break", cited(full)],
                observed=len(ds),
            )
        )
    # heard without another break: the first transmission or a retry of the same sequence
    # (a sensor slow to wake after the break is R-7.0-05/07's business, not this rule's)
    unbroken = [a for a in again.start.attempts if a.sequence == 0]
    late = late_among(
        "R-4.4.5.1-03",
        [again.start, *again.data],
        f"after the abort {code} delivered {again.value_count} values, "
        f"{target.value_count} before it",
    )
    if late is not None and again.value_count < target.value_count:
        case.add(late)
    elif why := unheard(again.start, brk2) or first_sequence_unheard(again.start, brk2):
        case.add(
            inconclusive(
                "R-4.4.5.1-03", why, evidence=[f"t={brk2.start:.4f} s: break", cited(again.start)]
            )
        )
    elif not again.start.answered:
        case.add(
            failed(
                "R-4.4.5.1-03",
                f"after the abort {code} got no reply",
                evidence=[f"t={brk2.start:.4f} s: break", cited(again.start)],
                observed=1,
            )
        )
    elif not any(a.reply_events for a in unbroken):
        case.add(
            failed(
                "R-4.4.5.1-03",
                f"ignored the {code} sent right after the aborting "
                "break (it answered only after another break)",
                evidence=[f"t={brk2.start:.4f} s: break", cited(again.start)],
                observed=1,
            )
        )
    elif again.value_count < target.value_count:
        case.add(
            failed(
                "R-4.4.5.1-03",
                f"after the abort {code} delivered "
                f"{again.value_count} values, {target.value_count} before it",
                evidence=cite([target.start, *target.data, again.start, *again.data]),
                observed=2,
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.5.1-03",
                f"the {code} sent right after the aborting break "
                f"worked as before ({again.value_count} values)",
                observed=1 + len(again.data),
            )
        )


def _reply_end(ex) -> float:
    """Where a measurement's ttt counts from (R-4.4.5-04): its reply's last stop bit, or
    where the engine stopped listening when nothing came."""
    return ex.reply_events[-1].end if ex.answered else ex.end
