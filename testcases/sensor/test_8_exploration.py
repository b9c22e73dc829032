"""Property-based exploration: random but reproducible command sequences with invariants."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges.exploration import IDS, broken_finding, held_findings
from conformance.sensor.exploration import explore

requirements = pytest.mark.requirements


@pytest.mark.needs("break")
@requirements(*IDS)
@pytest.mark.preconditions(
    listening=("R-4.0-01",),
    address=("R-4.3-01",),
    none=tuple(r for r in IDS if r not in ("R-4.0-01", "R-4.3-01")),
)
def test_random_command_sequences(sensor, case):
    """Random sequences of valid, foreign-address and malformed commands, breaks and pauses
    (derandomised): the sensor never answers another address, frames every reply, gets every
    CRC it sends right, and repeats D0 unchanged until a new measurement."""
    case.expect("every invariant holds after every step")
    run = explore(sensor)
    case.evidence(f"exploration: {run.steps} steps", run.exchanges)
    broken = run.broken  # every observation judged again: asked once
    if broken is not None:
        case.add(broken_finding(broken, run.failing_sequence, len(run.exchanges)))
    # silence to foreign addresses is evidence only from a sensor that answered its own; the
    # address replies are judged against is the one it answered at (moves were undone)
    own = [ex for ex in run.exchanges if ex.text.startswith(sensor.address)]
    if broken is None or broken.requirement != "R-4.0-01":
        case.requires(
            "listening",
            precondition.answered_control(own or run.exchanges[:1], "to foreign addresses"),
        )
    if broken is None or broken.requirement != "R-4.3-01":
        answered = [ex for ex in own if ex.answered]
        case.requires(
            "address",
            precondition.answers_at(
                answered[-1] if answered else (own[-1] if own else None),
                sensor.address,
                "no command of the exploration at its address was answered",
            ),
        )
    case.add(*held_findings(run.observations, run.steps))
