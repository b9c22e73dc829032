"""Bus cases (issue 23, item 2): what no single-device run can show. They run only when the
DUT shares its line with other sensors (``--address 0,1,3`` / ``--address all``); alone, they
are not part of the suite.

One stimulus (:func:`conformance.sensor.bus_round.concurrent_round`): the DUT's ``aC!``, then
every other sensor's, all finishing at about the same time, the others' data read first and
the DUT's last. Service requests meeting is not judged: only M-type measurements raise them,
and a recorder may not address another sensor while one runs (R-4.4.5-06).
"""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import bus as judge
from conformance.judges.cite import shown
from conformance.sensor.bus_round import BusRound, concurrent_round

requirements = pytest.mark.requirements
pytestmark = pytest.mark.bus


def bus_round(sensor) -> BusRound:
    """The round, once per run: both cases judge it."""
    return sensor.once(
        "bus-round", lambda: concurrent_round(sensor.master, sensor.address, sensor.others)
    )


def _others(sensor, case, made: BusRound, *, running: bool = False) -> bool:
    """The DUT answered a! just before, and at least one other sensor answered while the
    DUT's measurement waited (``running``: before its ttt ran out): else there was nothing
    on the bus to judge it by."""
    if not made.control.answered:
        unmet = precondition.Unmet(
            "others", f"the DUT did not answer {shown(made.control)} before the round"
        )
    elif not made.other_replies(running=running):
        unmet = precondition.Unmet(
            "others",
            f"none of the sensors at {', '.join(sorted(sensor.others))} answered while the "
            "DUT's measurement " + ("could still run (before its ttt)" if running else "waited"),
        )
    else:
        unmet = None
    return case.requires("others", unmet)


@requirements("R-4.4.7-05")
@pytest.mark.preconditions("supported", "others")
def test_concurrent_kept_while_others_answer(sensor, case):
    """Concurrent measurements on every sensor at once, data collected in turn: the DUT's
    measurement survives the commands to the others, their replies and their data."""
    case.expect("the DUT's aC! delivers all its values, read after every other sensor's data")
    undisturbed = sensor.measurement("C")
    made = bus_round(sensor)
    case.evidence("the round: aC! to every sensor, then their data", [made.control, made.dut])
    case.evidence("the others' replies while it ran", made.other_replies(running=True))
    served = bool(made.dut.ttt) and bool(made.dut.count) and undisturbed.value_count > 0
    if not case.requires(
        "supported",
        precondition.served(served, "the DUT's aC! announced no values or ttt 000"),
    ):
        return
    if not _others(sensor, case, made, running=True):
        return
    during = made.other_replies(running=True)
    case.extend(judge.kept_through_bus(made.dut, undisturbed.value_count, during))


@requirements("R-4.0-01")
@pytest.mark.preconditions("others")
def test_silent_while_others_are_addressed(sensor, case):
    """While its own data wait, the DUT ignores the other sensors' commands and replies,
    their data included (their measurements finished with its own: who answers next is the
    one asked)."""
    case.expect("no line starting with the DUT's address between its atttnn and its aD0!")
    made = bus_round(sensor)
    case.evidence("the DUT's wait, other sensors talking", made.window)
    if not _others(sensor, case, made):
        return
    case.extend(judge.silent_among_others(sensor.address, made.window, made.other_replies()))
