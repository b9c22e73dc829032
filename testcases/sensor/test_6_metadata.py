"""Section 6 (v1.4): identify-measurement commands and parameter metadata."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as xjudge
from conformance.judges import metadata as judge
from conformance.judges.stalled import through_stall
from conformance.judges.support import serves_continuous
from conformance.judges.tally import Tally
from conformance.protocol.commands import (
    C_FAMILY,
    HV_FAMILY,
    M_FAMILY,
    SERVICE_REQUEST_KINDS,
    Kind,
    described,
)
from conformance.protocol.responses import parse_measurement_reply_for, split_line
from conformance.protocol.values import split_values
from conformance.transcript import TOOL, EventKind, decode_7e1, escape
from conformance.verdicts import failed, inconclusive, passed
from conformance.view.runs import runs

requirements = pytest.mark.requirements
DESCRIBED = M_FAMILY + C_FAMILY + HV_FAMILY
META_IDS = ("R-6.2-01", "R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2-07", "R-6.2.1-01", "R-6.2.2-01")


def identify(sensor, code):
    return sensor.exchange(f"I{code}")


@requirements("R-6.1-01")
@pytest.mark.preconditions("none")
def test_identify_measurement_answered(sensor, case):
    """A v1.4 sensor answers every identify-measurement command (aIM! ... aIHB!)."""
    case.expect("a reply to each of the 43 identify forms")
    exchanges = [identify(sensor, code) for code in DESCRIBED]
    case.evidence("identify-measurement commands", exchanges)
    # its aI! text to aIM!: a parser that matched the 'I' alone, no identify-measurement
    # served (the twenty-first round's Due sketch answered all 43 so)
    echoed = _identification_echoed(
        "R-6.1-01", exchanges, sensor.exchange("I"), "a measurement's reply"
    )
    if echoed is not None:
        case.add(echoed)
        return
    case.add(
        xjudge.answered("R-6.1-01", exchanges, "v1.4 makes them mandatory", late_is_reply=True)
    )


def _identification_echoed(rule: str, exchanges: list, ident, served: str):
    """FAIL ``rule`` where any of ``exchanges`` drew the sensor's ``aI!`` reply (``ident``):
    those commands were not served as ``served`` names, whatever the text's framing; None
    where none did."""
    echoed = [ex for ex in exchanges if _is_identification(ex, ident)]
    if not echoed:
        return None
    return failed(
        rule,
        f"answered with its aI! identification, not {served}: "
        + ", ".join(xjudge.shown(e) for e in echoed[:4])
        + (f" (+{len(echoed) - 4} more)" if len(echoed) > 4 else ""),
        evidence=xjudge.cite([*echoed, ident]),
        observed=len(exchanges),
    )


def _is_identification(ex, ident) -> bool:
    """Whether ``ex`` (an identify-measurement or metadata command) drew the sensor's ``aI!``
    reply: an ``atttn`` or a record (``a,`` ...) can never be that text, so the command was
    not served."""
    return ex.answered and ident.answered and ex.reply_text == ident.reply_text


@requirements("R-6.1-02")
@pytest.mark.preconditions("supported")
def test_identify_matches_measurement(sensor, case):
    """Each identify reply equals the reply of the command without the I (decision A9)."""
    case.expect("same atttn/atttnn/atttnnn shape and count; a ttt difference only warns")
    pairs = [(identify(sensor, code), sensor.measurement(code)) for code in DESCRIBED]
    case.evidence("identify replies", [p[0] for p in pairs])
    both = any(i.answered and m.start.answered for i, m in pairs)
    case.requires(
        "supported",
        precondition.shown_supported(both, "no identify command and its measurement both answered"),
    )
    case.extend(judge.identify_matches(pairs))


@pytest.mark.needs("unsolicited")
@requirements("R-6.1-03")
@pytest.mark.preconditions("buffered", "supported")
def test_identify_starts_nothing(sensor, case):
    """An identify command starts no measurement: no service request, earlier data intact."""
    case.expect("no character after aIM!/aIC!/aIHA!; the D replies read before still come back")
    m = next((m for m in sensor.family(("M", "MC", "V", *M_FAMILY)) if m.value_count), None)
    if not case.requires("buffered", precondition.buffered(m, "measurement")):
        return
    fresh = sensor.fresh_measurement(m.command.text()[1:-1])

    def reread():
        # the same idle (the line marking past the 100 ms after which any sensor is in
        # standby, R-7.0-15: SensorSession.to_standby) and break before each read: only
        # the pokes differ. Counted from the line's last activity, so the long listening
        # after the pokes already is the second read's idle (issue 22)
        sensor.to_standby()
        return [sensor.fresh_exchange(ex.text[1:-1]) for ex in fresh.data]

    control = reread()
    first = len(sensor.link.transcript)
    pokes = [sensor.fresh_exchange(f"I{code}") for code in ("M", "C", "HA", "V")]
    heard = sensor.listen_until(_service_request_deadline(sensor, pokes))
    # a service request that came while the tool was still sending the identify commands
    # (one soon after aIM!) was taken in as a later command's stray characters, not heard
    heard = _requests_between(sensor, first, pokes, heard) + heard
    again = reread()
    case.evidence(
        "measurement, D again (control), identify commands, listening, D again",
        [fresh, *control, *pokes, heard, *again],
    )
    before = [ex.reply_text for ex in control]
    after = [ex.reply_text for ex in again]
    if heard:
        case.add(
            failed(
                "R-6.1-03",
                f"sent '{escape(decode_7e1(heard))}' after identify commands (a service request?)",
                evidence=xjudge.cite(pokes) + [xjudge.heard(heard, "then, unasked")],
                observed=len(pokes),
            )
        )
    elif not case.requires(
        "supported",
        precondition.shown_supported(
            any(ex.answered for ex in pokes),
            "no identify command (aIM!, aIC!, aIHA!, aIV!) was answered: nothing shows the "
            "sensor took one for an identify command (R-6.1-01)",
            xjudge.cite(pokes),
        ),
    ):
        return
    elif not fresh.value_count:
        # empty replies re-read as empty replies show no data kept: there were none to
        # disturb (buffer-cleared-by-break beside metadata-crc-sticks, seed 4054)
        case.add(
            inconclusive(
                "R-6.1-03",
                f"{fresh.command} delivered no values this time, so there were no data "
                "for the identify commands to change",
                observed=1,
            )
        )
    elif [ex.reply_text for ex in fresh.data] != before:
        case.add(
            inconclusive(
                "R-6.1-03",
                "the data did not survive a plain re-read, so the "
                "identify commands cannot be blamed (see R-4.4.5-10)",
            )
        )
    elif before != after:
        case.add(
            failed(
                "R-6.1-03",
                "identify commands changed the data: "
                f"'{escape(''.join(before))}' became '{escape(''.join(after))}'",
                evidence=xjudge.cite([*control, *pokes, *again]),
                observed=len(before) + len(after),
            )
        )
    else:
        case.add(
            passed(
                "R-6.1-03",
                f"{sum(ex.answered for ex in pokes)} answered identify commands: no service "
                "request, data unchanged",
                observed=sum(ex.answered for ex in pokes) + len(again),
            )
        )


def _service_request_deadline(sensor, pokes) -> float:
    """Until when a service request could still follow the identify commands: a sensor that
    took ``aIM!`` for ``aM!`` (``aIV!`` for ``aV!``) owes its service request before the ttt
    of that measurement has passed since its reply (R-4.4.6-04), and the engine's own
    patience for a late one (``late_sr_grace``) is added, as after any M or V. The ttt is
    the larger of the measurement's own and the one the identify reply announced. ``aIC!``
    and ``aIHA!`` name measurements that send no service request (R-4.4.6-05). Each window
    runs from the end of its own identify command's exchange, not from the last one's: the
    listening ends when the latest of them has (issue 22: it began after ``aIV!`` and took
    the ttt of ``aM!`` from there)."""
    grace = sensor.master.policy.late_sr_grace
    latest = sensor.link.now()
    for ex in pokes:
        target = described(ex.command)
        if target.kind not in SERVICE_REQUEST_KINDS:
            continue
        ttt = sensor.measurement(target.text()[1:-1]).ttt or 0
        if ex.answered:
            announced = parse_measurement_reply_for(split_line(ex.reply_text)[0], ex.command)
            ttt = max(ttt, announced.ttt or 0)
        latest = max(latest, ex.end + ttt + grace)
    return latest


def _requests_between(sensor, first: int, pokes, heard) -> list:
    """The complete service requests (``a<CR><LF>``, R-4.4.6-01) of the sensor's address on
    the wire since transcript index ``first`` that are neither a reply to one of ``pokes``
    nor among ``heard``: what the sensor sent unasked while the tool was still sending the
    identify commands. Only service requests: other characters after a reply are that
    reply's own framing fault, judged by its rules."""
    own = {id(e) for ex in pokes for a in ex.attempts for e in a.reply_events}
    own |= {id(e) for e in heard}
    dut = [
        e
        for e in sensor.link.transcript.since(first)
        if e.kind is EventKind.CHAR and e.origin != TOOL and id(e) not in own
    ]
    return [e for run in runs(dut) if decode_7e1(run) == f"{sensor.address}\r\n" for e in run]


def _metadata_plan(sensor):
    """(exchange, crc expected, index valid) for every index of every described command
    (valid None where only the identify reply gave the count, :func:`judge.records`), and
    the described commands whose count is unknown (:func:`_announced`)."""
    plan, unread = [], []
    for code in DESCRIBED:
        m = sensor.measurement(code)
        count, ident = _announced(sensor, code, m)
        if count is None:
            if m.start.answered or ident.answered:
                unread.append((m.start, ident))
            continue
        crc = m.command.returns_crc
        valid = True if ident is None else None  # None: a count only aIX! gave
        indices = range(1, count + 1)
        if code[:2] in ("MC", "CC"):  # the CRC twin describes the same values: ends suffice
            indices = sorted({1, count}) if count else ()
        for i in indices:
            plan.append((sensor.exchange(f"I{code}_{i:03d}"), crc, valid))
    return plan, unread


def _announced(sensor, code, m):
    """The value count of ``code`` and the identify exchange asked for it (None when the
    measurement's count sufficed): the measurement's own count, else the one its identify
    command announces (R-6.2-07 counts from that one). None when neither reply gives a
    count, though one of them answered: the records of that group cannot be counted, and a
    PASS over the other groups' records says nothing of them (issue 22's false PASS of
    measure-ttt-two-digits + metadata-missing-record)."""
    if m.count is not None:
        return m.count, None
    ident = identify(sensor, code)
    return judge.announced_count(ident), ident


@requirements(*META_IDS)
@pytest.mark.preconditions("supported")
def test_parameter_metadata(sensor, case):
    """Metadata replies 'a,field1,field2[,...];[CRC]' for every announced value: printable
    fields without ',' or ';', at most 75 characters through ';', units always present."""
    case.expect("one well-formed record per value index 1..n of every measurement")
    plan, unread = _metadata_plan(sensor)
    case.evidence("metadata commands", [p[0] for p in plan])
    if not case.requires(
        "supported", precondition.served(bool(plan), "no measurement announces values")
    ):
        return
    case.extend(judge.records(plan, case.requirements))
    case.extend(judge.uncounted_groups(unread, case.requirements))
    # its aI! text to aIM_001!: a parser that matched the 'I' alone served no metadata
    # command, however its framing reads (outside31: an EnviroDIY-based test slave answered
    # all 30 so, and R-6.2-01 PASSed "conforms (30 checked)")
    commands = [ex for ex, _, _ in plan]
    echoed = _identification_echoed("R-6.2-01", commands, sensor.exchange("I"), "a metadata record")
    if echoed is not None:
        case.add(echoed)


@requirements("R-6.2-05")
@pytest.mark.preconditions("supported")
def test_metadata_invalid_index(sensor, case):
    """Index 000 and an index above the count get 'a<CR><LF>' (or 'a<CRC><CR><LF>')."""
    case.expect("the invalid-index reply, with a CRC where the command carries one")
    plan = []
    for code in ("M", "MC", "C", "CC", "HA", "HB", "M9", "C9"):
        m = sensor.measurement(code)
        if m.count is None:
            continue  # a malformed reply gives no count to go past (judged by its own rule)
        crc = m.command.returns_crc
        plan.append((sensor.exchange(f"I{code}_000"), crc, False))
        plan.append((sensor.exchange(f"I{code}_{(m.count or 0) + 1:03d}"), crc, False))
    case.evidence("metadata with invalid indices", [p[0] for p in plan])
    if not case.requires(
        "supported", precondition.shown_supported(bool(plan), "no measurement gave a count")
    ):
        return
    case.extend(judge.records(plan, ("R-6.2-05",)))


@requirements("R-6.2-06")
@pytest.mark.preconditions("supported")
def test_continuous_metadata(sensor, case):
    """For each continuous command, aIRn_001!, _002!, ... answer in turn, ended by the
    invalid-index reply, one record for each value aRn! returns."""
    case.expect("records 001..k, then the invalid-index reply, k = the values of aRn!")
    tally = Tally(("R-6.2-06",))
    evidence = []
    for i in range(10):
        r = sensor.exchange(f"R{i}")
        if not serves_continuous(r):
            continue
        body, _ = split_line(r.reply_text)
        values = len(split_values(body[1:]))
        for code, crc in ((f"R{i}", False), (f"RC{i}", True)):
            seq = []
            for index in range(1, 100):
                ex = sensor.exchange(f"I{code}_{index:03d}")
                seq.append(ex)
                body = ex.reply_text.rstrip("\r\n")
                if not ex.answered or "," not in body:
                    break
            evidence += seq
            label = f"aI{code}_nnn!"
            tally.observe(label)
            last = seq[-1]
            if xjudge.undecided_if_late(tally, last, ["R-6.2-06"]):
                continue  # its reply came after the retries: R-7.0-10's, not a missing one
            here = through_stall(tally, last.stall)  # a read the host stalled over is cut
            if len(seq) == 1:
                here.fail("R-6.2-06", label, f"no record for {escape(seq[0].text)}")
            elif not last.answered:
                here.fail(
                    "R-6.2-06",
                    label,
                    f"{escape(last.text)} got no reply instead of the invalid-index reply",
                )
            elif "," in last.reply_text:
                here.fail("R-6.2-06", label, "no invalid-index reply after 99 records")
            elif crc and len(last.reply_text.rstrip("\r\n")) != 4:
                here.fail("R-6.2-06", label, f"end reply '{escape(last.reply_text)}' lacks the CRC")
            elif len(seq) - 1 != values:
                here.fail(
                    "R-6.2-06",
                    label,
                    f"{len(seq) - 1} record(s), but aR{i}! returns {values} value(s)",
                )
    case.evidence("continuous metadata", evidence)
    if not case.requires(
        "supported",
        precondition.served(bool(evidence), "the sensor serves no continuous measurement"),
    ):
        return
    case.extend(tally.findings("records in turn, closed by the invalid-index reply"))
    _ = Kind
