"""Section 5 (v1.4): high-volume ASCII (aHA!) and binary (aHB!, aDBn!) measurements."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as judge
from conformance.judges.empty_packet import judge_empty_packets
from conformance.judges.stalled import unless_stalled
from conformance.judges.support import holds_values
from conformance.protocol.responses import split_line
from conformance.sensor.session import shows_support
from conformance.verdicts import failed, inconclusive, passed, warned

requirements = pytest.mark.requirements


FEATURE = {"HA": "high_volume_ascii", "HB": "high_volume_binary"}
FORMAT_RULE = {"HA": "R-5.1-01", "HB": "R-5.2-01"}


def _text_reply(ex) -> bool:
    """Whether ``ex`` was answered with text that has no digit after the address ('aUNKN'):
    neither the a000000 of a sensor without high volume nor a start reply, malformed or not."""
    body, _ = split_line(ex.reply_text)
    return ex.answered and bool(body[1:]) and not any(c.isdigit() for c in body[1:])


def _support_undecided_if_late(case, starts, prefix: str = "") -> bool:
    """Whether any of the high-volume ``starts`` was answered only after its window (its
    reply unread: no "no values" was seen), which leaves support undecided: the precondition
    unmet as INCONCLUSIVE, not N/A (replies-after-retry: R-5.1-01 N/A "not supported" where
    0HA!'s reply was only late, and beside high-volume-two-digit-count the count rules' PASS
    hid 0HA!'s, seed 4900)."""
    late = [(ex, text) for ex in starts if (text := xjudge.answered_late(ex))]
    if not late:
        return False
    case.requires(
        "supported",
        precondition.shown_supported(
            False,
            prefix + "; ".join(text for _, text in late) + " (R-7.0-10 judges its timing), so"
            " whether the sensor has high volume is undecided",
            [xjudge.cited(ex) for ex, _ in late],
        ),
    )
    return True


def _unsupported(case, sensor, code):
    """N/A only for a well-formed 'no values' reply; a malformed reply is judged as support,
    but text with no digit ('aUNKN', seed 4167) leaves support undecided. A sensor declared
    to support the command must not answer 'no values'."""
    m = sensor.measurement(code)
    if _text_reply(m.start) and not sensor.feature(FEATURE[code]):
        case.requires(
            "supported",
            precondition.shown_supported(
                False,
                f"a{code}! answered {xjudge.shown(m.start)}: text, no start reply, so"
                " whether the sensor has high volume is undecided",
                [xjudge.cited(m.start)],
            ),
        )
        return True
    if shows_support(m):
        case.requires("supported", None)
        return False
    if sensor.feature(FEATURE[code]) and FORMAT_RULE[code] in case.requirements:
        case.add(
            failed(
                FORMAT_RULE[code],
                f"declared to support a{code}! but it answered {xjudge.shown(m.start)}",
                evidence=[xjudge.cited(m.start)],
                observed=1,
            )
        )
        case.requires(
            "supported",
            precondition.served(False, "no high-volume data to judge", [xjudge.cited(m.start)]),
            only=[r for r in case.requirements if r != FORMAT_RULE[code]],
        )
        return True
    if _support_undecided_if_late(case, [m.start], f"a{code}!: "):
        return True
    case.requires(
        "supported",
        precondition.served(
            False, f"a{code}! announced no values: high-volume {code} not supported"
        ),
    )
    return True


@requirements("R-5.4-02")
@pytest.mark.preconditions("none")
def test_high_volume_optional(sensor, case):
    """A v1.4 sensor without high-volume support answers aHA!/aHB! with a000000."""
    case.expect("'atttnnn' if supported, else 'a000000<CR><LF>'")
    starts = [sensor.measurement(c).start for c in ("HA", "HB")]
    case.evidence("aHA!, aHB!", starts)
    odd = []
    read = [(ex, xjudge.late_only("R-5.4-02", ex, ex.text)) for ex in starts]
    late = [f for _, f in read if f]
    for ex, late_finding in read:
        if late_finding:
            continue  # late: R-7.0-10's, its content unread
        body, _ = split_line(ex.reply_text)
        if not ex.answered or (body[4:7] == "000" and body[1:] != "000000") or _text_reply(ex):
            odd.append(ex)
    if odd:
        case.add(
            warned(
                "R-5.4-02",
                "without high-volume support expected 'a000000': "
                + "; ".join(xjudge.shown(e) for e in odd),
                evidence=xjudge.cite(odd),
                observed=len(starts),
            )
        )
    elif late:
        case.add(late[0])  # a reply came after its window: its content was not read
    else:
        case.add(
            passed("R-5.4-02", "; ".join(xjudge.shown(e) for e in starts), observed=len(starts))
        )


@requirements("R-5.1-01", "R-5.1-02", "R-5.1-03")
@pytest.mark.preconditions("supported")
def test_high_volume_ascii(sensor, case):
    """aHA! answers atttnnn; data come from aD0..aD999! (no leading zeros) with at most 75
    value characters a reply and always a CRC."""
    case.expect("'atttnnn'; D replies with CRC, <= 75 value chars, past D9 when needed")
    m = sensor.measurement("HA")
    case.evidence("aHA! and its D replies", m)
    if _unsupported(case, sensor, "HA"):
        return
    case.extend(judge.judge([m], case.requirements, sensor.version))


@pytest.mark.needs("binary")
@requirements(
    "R-5.2-01", "R-5.2-02", "R-5.2-03", "R-5.2-04", "R-5.2-05", "R-5.2-07", "R-5.2.1-01", "R-4.1-03"
)
@pytest.mark.preconditions("supported")
def test_high_volume_binary(sensor, case):
    """aHB! answers atttnnn; aDBn! packets: 8N1 address, size, type, payload, CRC LSB first;
    one type a packet; payload a whole number of values, at most 1000 bytes; nnn values in
    all."""
    case.expect("packets that parse, with correct CRC, adding up to nnn values")
    m = sensor.measurement("HB")
    case.evidence("aHB! and its DB packets", m)
    if _unsupported(case, sensor, "HB"):
        return
    case.extend(judge.judge([m], case.requirements, sensor.version))


@pytest.mark.needs("binary")
@requirements("R-5.2-06")
@pytest.mark.preconditions("supported")
def test_empty_packet_past_data(sensor, case):
    """aDBn! past the data returns the 6-byte empty packet (size 0, type 0)."""
    case.expect("address, 00 00, 00, CRC: 6 bytes, for the first index past the data and DB999")
    if _unsupported(case, sensor, "HB"):
        return
    # read right after the shared aHB! measurement: the DB indices refer to the latest one
    exchanges = sensor.packets_past_data()
    case.evidence("aDBn! past the data", exchanges)
    case.add(judge_empty_packets(exchanges, sensor.address))


def _in_part(marking: float | None, what: str) -> precondition.Unmet | None:
    """The one-shot hearing check as a partial precondition: a measurement that lost values
    after the break and a foreign command is a FAIL whether or not that command was heard, so
    an unheard probe while HB ran must not void the FAIL HA already earned."""
    unmet = precondition.heard_one_shot(marking, what)
    return None if unmet is None else replace(unmet, partial=True)


@pytest.mark.needs("break", "unsolicited")
@requirements("R-5.3-01")
@pytest.mark.preconditions("supported", "buffered", "listening")
def test_high_volume_is_concurrent(sensor, case):
    """HA/HB behave as concurrent measurements: no service request, not disturbed by a break
    and other traffic, aborted by a valid command to the sensor itself."""
    case.expect("no SR; all values after a break + foreign command; none after an own aI!")
    codes = [c for c in ("HA", "HB") if sensor.supports(c)]
    starts = [sensor.measurement(c).start for c in ("HA", "HB")]
    if not codes and _support_undecided_if_late(case, starts):
        return
    if not case.requires("supported", precondition.served(bool(codes), "no high-volume support")):
        return
    ms = [sensor.measurement(c) for c in codes]
    if any(m.ttt for m in ms):
        case.extend(judge.judge([m for m in ms if m.ttt], case.requirements, sensor.version))
    other = sensor.foreign_address()
    for baseline in ms:
        code = baseline.command.text()[1:-1]
        if not baseline.ttt or not baseline.value_count:
            continue
        kept, poke1 = sensor.disturbed_measurement(baseline.command, f"{other}I!")
        # an empty D0 after the own aI! shows the abort emptied the buffer only where the
        # buffer keeps values through what comes before it without an abort (read to the
        # end, standby, a break: abort-keeps-old-data beside buffer-cleared-by-break or
        # data-lost-after-standby PASSed 'aI! aborted it', as R-4.4.7.1-02 did)
        control = sensor.values_after_standby(kept)
        stopped, poke2 = sensor.disturbed_measurement(baseline.command, f"{sensor.address}I!")
        case.evidence(
            f"{code}: break + {other}I!, standby, break and D0, then {sensor.address}I!,"
            " while running",
            [kept, poke1, *control, stopped, poke2],
        )
        if kept.value_count < baseline.value_count:
            fewer = failed(
                "R-5.3-01",
                f"a{code}! delivered {kept.value_count} values after a "
                f"break and {other}I!, {baseline.value_count} undisturbed",
                evidence=xjudge.cite([baseline.start, kept.start, poke1, *kept.data]),
                observed=2,  # the undisturbed measurement and the disturbed one
            )
            # counted over every D read: one the host stalled over may have cut the count
            case.add(unless_stalled(fewer, kept.data, together=True))
        elif not case.requires("listening", _in_part(sensor.hearing_marking(), f"{other}I!")):
            pass  # its silence to the foreign command shows nothing: undecided
        elif not poke2.answered:
            case.add(
                inconclusive(
                    "R-5.3-01",
                    f"{sensor.address}I! was not answered, so the abort cannot be judged",
                )
            )
        elif stopped.value_count:
            case.add(
                failed(
                    "R-5.3-01",
                    f"a{code}! was not aborted by {sensor.address}I! "
                    f"({stopped.value_count} values still delivered)",
                    evidence=xjudge.cite([stopped.start, poke2, *stopped.data]),
                    observed=1,
                )
            )
        elif not any(holds_values(d, kept.binary) for d in control):
            case.add(
                inconclusive(
                    "R-5.3-01",
                    f"a{code}! survived a break and {other}I!, and no values came after"
                    f" {sensor.address}I!, but the buffer was not shown to hold values up to"
                    " the abort (old data kept look the same): read to its end, standby, a"
                    " break and a D read gave none either: "
                    + "; ".join(xjudge.shown(d) for d in control),
                    observed=2 + len(control),
                )
            )
        else:
            case.add(
                passed(
                    "R-5.3-01",
                    f"a{code}! survived a break and {other}I!, and {sensor.address}I! aborted it",
                    observed=2,  # the kept and the stopped measurement
                )
            )
    timed = [m for m in ms if m.ttt]
    if not case.record.findings:
        case.requires(
            "supported",
            precondition.served(
                False, "no high-volume measurement with ttt > 0 and values to disturb"
            ),
        )
        return
    # the service-request half alone is not the rule: without values to disturb, traffic
    # and aborts go unjudged, and the service-request half's PASS does not stand for it
    case.requires(
        "buffered",
        precondition.buffered_any(
            timed,
            detail="no HA/HB measurement with ttt > 0 delivered values, so whether a break, "
            "other traffic or an own command disturbs one cannot be judged",
        ),
    )
