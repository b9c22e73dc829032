"""Sections 4.4.13-4.4.13.1: extended commands and multi-line text (opt-in: only the extended
commands the declaration lists are ever sent)."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import extended as judge

requirements = pytest.mark.requirements


def declared(sensor):
    return list(sensor.declaration.extended)


@requirements("R-4.4.13-01", "R-4.4.13-02")
@pytest.mark.preconditions("supported")
def test_extended_commands(sensor, case):
    """Replies to extended commands start with the address and end with CR LF; the commands
    take the aX...! form (SHOULD)."""
    case.expect("'a...<CR><LF>' for each declared extended command; names start with X")
    names = declared(sensor)
    absent = precondition.served(
        bool(names),
        "no extended command declared (extended commands are opt-in: list "
        "them under [features] extended in the declaration)",
    )
    if not case.requires("supported", absent):
        return
    exchanges = [sensor.exchange(name) for name in names]
    case.evidence("declared extended commands", exchanges)
    case.extend(judge.extended_replies(exchanges, sensor.address))


@pytest.mark.needs("unsolicited")
@requirements("R-4.4.13.1-01", "R-4.4.13.1-02", "R-4.4.13.1-03")
@pytest.mark.preconditions("supported")
def test_multiline_text(sensor, case):
    """Multi-line replies: STX after the address, ETX after the last CR LF, at most 75
    characters a line, no CRC, lines at most 150 ms apart (decision A10)."""
    case.expect("'a<STX>line<CR><LF>...<CR><LF><ETX>' framing and timing")
    names = declared(sensor)
    exchanges = [sensor.exchange(name) for name in names]
    multi = [ex for ex in exchanges if judge.is_multiline(ex)]
    absent = precondition.served(
        bool(multi),
        "no declared extended command answered with multi-line text (multi-line text is optional)"
        if names
        else "no extended command declared (opt-in)",
    )
    if not case.requires("supported", absent):
        return
    case.evidence("multi-line replies", multi)
    case.extend(judge.multiline(multi, sensor.address, sensor.uncertainty))
