"""Sections 4.4.9-4.4.11: additional measurements aMn!/aMCn!, aCn!/aCCn!, and aV!."""

from __future__ import annotations

import pytest

from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as judge
from conformance.protocol.responses import split_line
from conformance.verdicts import passed, warned

requirements = pytest.mark.requirements
MN = tuple(f"M{i}" for i in range(1, 10)) + tuple(f"MC{i}" for i in range(1, 10))
CN = tuple(f"C{i}" for i in range(1, 10)) + tuple(f"CC{i}" for i in range(1, 10))


@requirements("R-4.4.9-01")
def test_additional_m_answered(sensor, case):
    """Every aM1..aM9! and aMC1..aMC9! gets a reply, defined or not."""
    case.expect("a reply to each of the 18 commands")
    starts = [m.start for m in sensor.family(MN)]
    case.evidence("aM1..9!, aMC1..9!", starts)
    case.add(xjudge.answered("R-4.4.9-01", starts, "silence does not comply"))


@requirements("R-4.4.10-01")
def test_additional_c_answered(sensor, case):
    """Every aC1..aC9! and aCC1..aCC9! gets a reply, defined or not."""
    case.expect("a reply to each of the 18 commands")
    starts = [m.start for m in sensor.family(CN)]
    case.evidence("aC1..9!, aCC1..9!", starts)
    case.add(xjudge.answered("R-4.4.10-01", starts, "silence does not comply"))


def _undefined(sensor, codes, rid, expected_tail):
    zero = [m for m in sensor.family(codes) if m.start.answered and m.count == 0]
    if not zero:
        return [xjudge.na(rid, "every numbered group is defined")]
    odd = [m for m in zero if split_line(m.start.reply_text)[0][1:] != expected_tail]
    if odd:
        return [
            warned(
                rid,
                "undefined group answered "
                + ", ".join(xjudge.shown(m.start) for m in odd[:3])
                + f"; expected 'a{expected_tail}'",
            )
        ]
    return [passed(rid, f"{len(zero)} undefined group(s) answered 'a{expected_tail}'")]


@requirements("R-4.4.9-02")
def test_undefined_m_group(sensor, case):
    """An undefined aMn! answers a0000."""
    case.expect("'a0000<CR><LF>' for a group the sensor does not define")
    case.evidence("aM1..9!, aMC1..9!", [m.start for m in sensor.family(MN)])
    case.extend(_undefined(sensor, MN, "R-4.4.9-02", "0000"))


@requirements("R-4.4.10-02")
def test_undefined_c_group(sensor, case):
    """An undefined aCn! answers a00000."""
    case.expect("'a00000<CR><LF>' for a group the sensor does not define")
    case.evidence("aC1..9!, aCC1..9!", [m.start for m in sensor.family(CN)])
    case.extend(_undefined(sensor, CN, "R-4.4.10-02", "00000"))


@requirements("R-4.4.11-01")
def test_verification(sensor, case):
    """aV! behaves like aM!: atttn, service request when ttt > 0, D replies of at most 35
    value characters in D format."""
    case.expect("the aM! rules applied to aV!")
    m = sensor.measurement("V")
    case.evidence("aV!", m)
    if not m.start.answered:
        case.add(xjudge.failed("R-4.4.11-01", "aV! got no reply"))
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
    problems = [f for f in judge.judge([m], ids, sensor.version) if f.verdict.name in ("FAIL",)]
    if problems:
        case.add(
            xjudge.failed(
                "R-4.4.11-01",
                "aV! does not behave like aM!: "
                + "; ".join(f"{f.requirement}: {f.detail}" for f in problems[:3]),
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.11-01",
                f"aV! answered '{xjudge.escape(m.start.reply_text)}' "
                f"and delivered {m.value_count} value(s) like aM!",
            )
        )
