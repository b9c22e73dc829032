"""Sections 4.3-4.4: the commands a recorder must be able to issue and the addresses it uses."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.capabilities import judge_addresses, judge_commands_issued

from ._helpers import line_of

requirements = pytest.mark.requirements


@requirements("R-4.4-02")
@pytest.mark.preconditions("recorder")
def test_every_basic_command_and_family(recorder, case):
    """The recorder issues the basic commands (?!, a!, aI!, aAb!) and logs data from aM!,
    aMn!, aMC!, aV!, aC!, aCn!, aCC!, aRn! and aRCn!."""
    case.expect("each command sent, each answered validly, every announced value read")
    names = ("families", "basic-commands")
    line = line_of(recorder, case, *names)
    asked = [c for n in names for c in recorder.run(n).asked]
    case.add(judge_commands_issued(line, asked, recorder.uncertainty))


@requirements("R-4.3-03", "R-4.3-04")
@pytest.mark.preconditions("recorder")
def test_addresses(recorder, case):
    """Sensors at 0-9 can each be polled; letter addresses are an option."""
    case.expect("a valid exchange with each of the sensors at 0..9 (and A, z if supported)")
    line = line_of(recorder, case, "addresses")
    case.extend(judge_addresses(line, recorder.uncertainty))
