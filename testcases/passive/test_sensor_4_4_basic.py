"""Sensor rules, sections 4.4.1 and 4.4.13: the acknowledge reply and extended commands'
replies (multi-line text included), where the recording holds them."""

from __future__ import annotations

from itertools import groupby

import pytest

from conformance.judges import extended
from conformance.judges.exchanges import reply_only_address
from conformance.protocol.commands import Kind

from ._helpers import heard, judged

requirements = pytest.mark.requirements


def _by_address(exchanges):
    ordered = sorted(exchanges, key=lambda ex: ex.command.address)
    return groupby(ordered, key=lambda ex: ex.command.address)


@requirements("R-4.4.1-01")
@pytest.mark.preconditions("heard")
def test_acknowledge_active(heard_sensors, case):
    """Every recorded reply to a! is the address alone, then CR LF."""
    case.expect("'a<CR><LF>' to each answered a!")
    asked = [ex for ex in heard_sensors.exchanges_of(Kind.ACKNOWLEDGE) if ex.answered]
    if not heard(case, asked, "no answered a!"):
        return
    case.evidence("recorded a! exchanges", asked)
    for ex in asked:
        case.add(reply_only_address(ex, ex.command.address, "R-4.4.1-01", "a!"))


@requirements("R-4.4.13-01", "R-4.4.13-02")
@pytest.mark.preconditions("heard")
def test_extended_commands(heard_sensors, case):
    """Replies to recorded extended commands run from the address to CR LF; the commands the
    sensor answers take the aX...! form (SHOULD)."""
    case.expect("'a...<CR><LF>' to each answered extended command")
    asked = heard_sensors.exchanges_of(Kind.EXTENDED)
    case.evidence("recorded extended commands", asked)
    if not heard(case, [ex for ex in asked if ex.answered], "no answered extended command"):
        return
    for address, group in _by_address(asked):
        judged(case, extended.extended_replies(list(group), address))


@requirements("R-4.4.13.1-01", "R-4.4.13.1-02", "R-4.4.13.1-03")
@pytest.mark.preconditions("heard")
def test_multiline_text(heard_sensors, case):
    """Recorded multi-line replies: STX after the address, ETX after the last CR LF, at most
    75 characters a line, lines at most 150 ms apart."""
    case.expect("'a<STX>line<CR><LF>...<CR><LF><ETX>' framing and timing")
    multi = [ex for ex in heard_sensors.exchanges_of(Kind.EXTENDED) if extended.is_multiline(ex)]
    if not heard(case, multi, "no multi-line reply"):
        return
    case.evidence("recorded multi-line replies", multi)
    for address, group in _by_address(multi):
        judged(case, extended.multiline(list(group), address, heard_sensors.uncertainty))
