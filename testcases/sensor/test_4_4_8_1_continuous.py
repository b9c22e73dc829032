"""Section 4.4.8.1: continuous measurements aR0..aR9! and aRC0..aRC9!."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as judge
from conformance.judges.support import serves_continuous
from conformance.verdicts import failed, passed

requirements = pytest.mark.requirements


def continuous_pairs(sensor):
    return {i: (sensor.exchange(f"R{i}"), sensor.exchange(f"RC{i}")) for i in range(10)}


@requirements("R-4.4.8.1-01", "R-4.4.8.1-03")
@pytest.mark.preconditions(supported=("R-4.4.8.1-01",), none=("R-4.4.8.1-03",))
def test_continuous_replies(sensor, case):
    """R and RC replies come at once, formatted like D replies with at most 75 value
    characters, RC with a CRC; an index the sensor does not serve gets the empty reply."""
    case.expect("'a<values>[<CRC>]<CR><LF>', or 'a<CR><LF>' / 'a<CRC><CR><LF>' (e.g. '0AP@')")
    pairs = continuous_pairs(sensor)
    case.evidence("aR0..aR9!, aRC0..aRC9!", [ex for pair in pairs.values() for ex in pair])
    case.extend(judge.continuous(pairs, case.requirements))
    served = [i for i, (ex, _) in pairs.items() if serves_continuous(ex)]
    declared = sensor.feature("continuous")
    if declared and not served:
        case.add(
            failed(
                "R-4.4.8.1-01",
                "declared to support continuous measurements, but aR0!..aR9! returned no values",
                evidence=judge.cite(ex for ex, _ in pairs.values()),
                observed=len(pairs),
            )
        )
    # not declared and no value in any reply: the feature is absent, its format not judged
    case.requires(
        "supported",
        precondition.served(
            bool(served) or declared is not False,
            "declared without continuous measurements, and aR0!..aR9! returned no values",
            judge.cite(ex for ex, _ in list(pairs.values())[:2]),
        ),
    )


@requirements("R-4.4.8.1-02")
@pytest.mark.preconditions("supported")
def test_continuous_independent(sensor, case):
    """Each Rn stands alone: asking for Rn first, straight after waking, still gives data."""
    case.expect("the same kind of reply to aRn! whether or not R0..R(n-1) came first")
    served = [
        i for i, (ex, _) in continuous_pairs(sensor).items() if i > 0 and serves_continuous(ex)
    ]
    if not case.requires(
        "supported",
        precondition.served(bool(served), "the sensor serves no continuous index above R0"),
    ):
        return
    index = served[-1]
    sensor.to_standby()  # standby, so the next command starts a fresh conversation
    sensor.master.send_break()
    sensor.fresh_exchange("I")
    ex = sensor.fresh_exchange(f"R{index}")
    case.evidence(f"aI! then aR{index}! with no lower R first", [ex])
    late = judge.late_only("R-4.4.8.1-02", ex, f"R{index} without the lower indices first")
    if late is not None:
        case.add(late)
    elif serves_continuous(ex):
        case.add(passed("R-4.4.8.1-02", f"R{index} alone: {judge.shown(ex)}", observed=1))
    else:
        case.add(
            failed(
                "R-4.4.8.1-02",
                f"R{index} without the lower indices first gave no values: {judge.shown(ex)}",
                evidence=[judge.cited(ex)],
                observed=1,
            )
        )
