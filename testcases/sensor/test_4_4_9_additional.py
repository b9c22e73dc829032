"""Sections 4.4.9-4.4.11: additional measurements aMn!/aMCn!, aCn!/aCCn!, and aV!."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as judge
from conformance.protocol.responses import split_line
from conformance.verdicts import inconclusive, passed, warned

requirements = pytest.mark.requirements
MN = tuple(f"M{i}" for i in range(1, 10)) + tuple(f"MC{i}" for i in range(1, 10))
CN = tuple(f"C{i}" for i in range(1, 10)) + tuple(f"CC{i}" for i in range(1, 10))


@requirements("R-4.4.9-01")
@pytest.mark.preconditions("none")
def test_additional_m_answered(sensor, case):
    """Every aM1..aM9! and aMC1..aMC9! gets a reply, defined or not."""
    case.expect("a reply to each of the 18 commands")
    starts = [m.start for m in sensor.family(MN)]
    case.evidence("aM1..9!, aMC1..9!", starts)
    case.add(xjudge.answered("R-4.4.9-01", starts, "silence does not comply", late_is_reply=True))


@requirements("R-4.4.10-01")
@pytest.mark.preconditions("none")
def test_additional_c_answered(sensor, case):
    """Every aC1..aC9! and aCC1..aCC9! gets a reply, defined or not."""
    case.expect("a reply to each of the 18 commands")
    starts = [m.start for m in sensor.family(CN)]
    case.evidence("aC1..9!, aCC1..9!", starts)
    case.add(xjudge.answered("R-4.4.10-01", starts, "silence does not comply", late_is_reply=True))


def _undefined(sensor, codes, rid, expected_tail):
    """Groups answered with a zero count, or not at all, are undefined: each should answer
    'a0...0'. Silence is judged here as a SHOULD (and as a MUST by R-4.4.9-01/R-4.4.10-01)."""
    ms = sensor.family(codes)
    zero = [m for m in ms if m.start.answered and m.count == 0]
    unheard = [m for m in ms if not m.start.answered]
    late = [m for m in unheard if xjudge.late_reply(m.start)]  # late, not silent: R-7.0-10's
    silent = [m for m in unheard if m not in late]
    if not zero and not silent:
        if late:
            shown = ", ".join(xjudge.late_shown(m.start) for m in late[:3])
            return [
                inconclusive(
                    rid,
                    f"answered only after the reply window: {shown}; whether a group is "
                    "undefined is not told by a reply the tool could not take",
                    evidence=xjudge.cite(m.start for m in late),
                    observed=len(late),
                )
            ]
        return [xjudge.na(rid, "every numbered group is defined")]
    odd = [m for m in zero if split_line(m.start.reply_text)[0][1:] != expected_tail] + silent
    if odd:
        shown = ", ".join(xjudge.shown(m.start) for m in odd[:3])
        return [
            warned(
                rid,
                f"undefined group answered {shown}; expected 'a{expected_tail}'",
                evidence=xjudge.cite(m.start for m in odd),
                observed=len(zero) + len(silent),
            )
        ]
    return [
        passed(
            rid, f"{len(zero)} undefined group(s) answered 'a{expected_tail}'", observed=len(zero)
        )
    ]


@requirements("R-4.4.9-02")
@pytest.mark.preconditions("none")
def test_undefined_m_group(sensor, case):
    """An undefined aMn! answers a0000."""
    case.expect("'a0000<CR><LF>' for a group the sensor does not define")
    case.evidence("aM1..9!, aMC1..9!", [m.start for m in sensor.family(MN)])
    case.extend(_undefined(sensor, MN, "R-4.4.9-02", "0000"))


@requirements("R-4.4.10-02")
@pytest.mark.preconditions("none")
def test_undefined_c_group(sensor, case):
    """An undefined aCn! answers a00000."""
    case.expect("'a00000<CR><LF>' for a group the sensor does not define")
    case.evidence("aC1..9!, aCC1..9!", [m.start for m in sensor.family(CN)])
    case.extend(_undefined(sensor, CN, "R-4.4.10-02", "00000"))


@requirements("R-4.4.11-01")
@pytest.mark.preconditions("supported")
def test_verification(sensor, case):
    """aV! behaves like aM!: atttn, service request when ttt > 0, D replies of at most 35
    value characters in D format."""
    case.expect("the aM! rules applied to aV!")
    m = sensor.measurement("V")
    case.evidence("aV!", m)
    if not m.start.answered:
        case.add(
            xjudge.failed(
                "R-4.4.11-01", "aV! got no reply", evidence=[xjudge.cited(m.start)], observed=1
            )
        )
        return
    ids = [
        "R-4.4.5-01",
        "R-4.4.5-02",
        "R-4.4.6-01",
        "R-4.4.6-02",
        "R-4.4.6-04",
        "R-4.4.5-08",
        "R-4.4-05",
        "R-4.4.8-01",
        "R-4.4.8-02",
        "R-4.4.8-03",
        "R-4.4.8-04",
    ]
    reference = sensor.measurement("M")
    if not case.requires(
        "supported",
        precondition.shown_supported(
            reference.start.answered,
            "aM! got no reply to compare aV! with",
            [xjudge.cited(reference.start)],
        ),
    ):
        return
    as_v = {f.requirement: f for f in judge.judge([m], ids, sensor.version)}
    as_m = {f.requirement: f for f in judge.judge([reference], ids, sensor.version)}
    broken = [rid for rid in ids if as_v[rid].verdict.name == "FAIL"]
    differ = [rid for rid in broken if as_m[rid].verdict.name == "PASS"]
    # a rule aM! was not shown to keep (its count of 0 left no D0 to judge, say): aV!'s
    # breaking it says nothing of a difference (groups-start-at-d1 beside measure-count-zero
    # FAILed this for R-4.4.8-04, which aM! had no values to show, seed 4072)
    unshown = [rid for rid in broken if as_m[rid].verdict.name != "FAIL" and rid not in differ]
    if differ:
        case.add(
            xjudge.failed(
                "R-4.4.11-01",
                "aV! breaks rules aM! keeps: "
                + "; ".join(f"{rid}: {as_v[rid].detail}" for rid in differ[:3]),
                evidence=[xjudge.cited(m.start), xjudge.cited(reference.start)]
                + [line for rid in differ for line in as_v[rid].evidence],
                observed=2,  # aV! and the aM! it is compared with
            )
        )
    elif unshown:
        case.add(
            inconclusive(
                "R-4.4.11-01",
                "aV! breaks rules aM! was not shown to keep: "
                + "; ".join(
                    f"{rid}: {as_v[rid].detail} (aM!: {as_m[rid].verdict.name})"
                    for rid in unshown[:3]
                ),
                evidence=[xjudge.cited(m.start), xjudge.cited(reference.start)],
                observed=2,
            )
        )
    elif m.ttt is None:
        # no ttt to wait out: the service-request rules were judged on neither reply, so
        # "breaks nothing aM! keeps" would rest on no observation of them (a missed
        # verify-no-service-request beside measure-ttt-two-digits, seed 4051)
        case.add(
            inconclusive(
                "R-4.4.11-01",
                f"aV! answered '{xjudge.escape(m.start.reply_text)}', which gives no ttt: "
                "whether it owes a service request (R-4.4.6-02) cannot be judged, so it "
                "cannot be shown to behave like aM!",
                evidence=[xjudge.cited(m.start)],
                observed=1,
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.11-01",
                f"aV! answered '{xjudge.escape(m.start.reply_text)}' and delivered "
                f"{m.value_count} value(s); every aM! rule it breaks, aM! breaks too",
                observed=1 + len(m.data),
            )
        )
