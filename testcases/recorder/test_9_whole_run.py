"""Rules judged over every transmission of every scenario: breaks and the marking after them,
command characters, character gaps, the bit rate, the 87 ms rule.

Each case asks for every applicable scenario itself (each runs once per run), so it judges
the same transmissions whatever order or selection the run was given."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.breaks import judge_break_rules, judge_breaks
from conformance.judges.recorder.commands import (
    judge_character_gaps,
    judge_command_bit_rate,
    judge_command_frame_lengths,
    judge_command_text,
)
from conformance.links.base import NO_BIT_TIMING
from conformance.verdicts import inconclusive

from ._helpers import line_of

requirements = pytest.mark.requirements


def _everything(recorder, case):
    return line_of(recorder, case, *recorder.applicable(), whole_run=True)


@requirements("R-7.0-02", "R-7.0-06")
@pytest.mark.preconditions("recorder")
def test_breaks(recorder, case):
    """Every break lasts at least 12 ms and is followed by at least 8.33 ms of marking."""
    case.expect("break >= 12 ms (-0.40); marking before the command >= 8.33 ms (-0.40)")
    case.extend(judge_breaks(_everything(recorder, case), recorder.uncertainty))


@requirements("R-7.0-17")
@pytest.mark.preconditions("recorder")
def test_break_when_due(recorder, case):
    """A break before every command to a new sensor and after more than 87 ms of marking."""
    case.expect("commands without a break only to the same sensor within 87 ms (+0.40)")
    found = judge_break_rules(_everything(recorder, case), recorder.uncertainty)
    case.extend(f for f in found if f.requirement == "R-7.0-17")


@requirements("R-4.2-01", "R-4.4-04", "R-4.3-01")
@pytest.mark.preconditions("recorder")
def test_command_text(recorder, case):
    """Commands are printable, start with an address and end with their only '!'."""
    case.expect("printable ASCII; the address first; '!' last and nowhere else")
    case.extend(judge_command_text(_everything(recorder, case), recorder.uncertainty))


@requirements("R-7.0-13", "R-7.0-01", "R-4.1-01")
@pytest.mark.preconditions("recorder")
def test_character_timing(recorder, case):
    """At most 1.66 ms between command characters (no tolerance), at 1200 baud."""
    case.expect("every gap inside a command <= 1.66 ms; characters one 8.33 ms frame apart")
    line = _everything(recorder, case)
    case.extend(judge_character_gaps(line, recorder.uncertainty))
    if recorder.served is not None:  # a PASS here would rest on the server's own spacing
        case.add(
            inconclusive(
                "R-4.1-01",
                "the served line receives the recorder's bytes already decoded and lays them "
                "one frame apart itself: their bit rate cannot be observed here",
            )
        )
    elif not recorder.link.info.bit_timing:
        case.add(inconclusive("R-4.1-01", NO_BIT_TIMING))
    elif recorder.link.info.frame_lengths:  # a firmware kit: each frame its own ten bits
        case.add(judge_command_frame_lengths(line, recorder.uncertainty))
    else:
        case.add(judge_command_bit_rate(line, recorder.uncertainty))
