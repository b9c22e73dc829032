"""The exploration's D0-repeat check (R-4.4.5-10) reads no D0 from a reply that may be the
command before's, late (outside28): the replies-after-retry sensor (every reply 80 ms after
its command, deaf until then) beside no-recovery-after-abort and parity-error, behind
``emulate --echo --usb-latency 16``, left 0D1!'s tries unanswered in their windows; its late
'0+12.50...' was taken by the 0D0! after them, and R-4.4.5-10 FAILed "D0 gave '0-5.00...',
then '0+12.50...' with no measurement between", where the sim's exact stamps left the rule
INCONCLUSIVE (the fault's declared outcome). A D0 that reads its own reply still counts."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from conformance.judges.exploration import Observation, judge
from conformance.sensor.exploration_record import Exploration, InvariantBroken
from conformance.sensor.exploration_steps import ExplorerSteps
from conformance.tool_recorder.records import Exchange
from tests.judges.test_late_before import _after_unanswered, _exchange

HELD = "0-5.00-3.75+1.25\r\n"  # what D0 read before
D1 = "0+12.50+13.75\r\n"  # D1's reply, 80 ms late


def _steps(replies: list[Exchange]) -> ExplorerSteps:
    """An ExplorerSteps whose master hands out ``replies`` in order."""
    queue = iter(replies)
    master = SimpleNamespace(transact=lambda text: next(queue), send_break=lambda: None)

    class Steps(ExplorerSteps):
        sensor = SimpleNamespace(address="0", master=master)  # type: ignore[assignment]
        record = Exploration()
        marking = None

    return Steps()


def _late_d1_then_d0() -> list[Exchange]:
    """0D0! answered HELD at -1 s; 0D1! unanswered at 0 s; 0D0! 30 ms after its window,
    taking D1's reply begun 80 ms after 0D1! ended (linked as the session's engine links a
    late sensor's: ``_after_unanswered``)."""
    first = _exchange("0D0!", -1.0, HELD)
    ex = _after_unanswered("0D1!", "0D0!", D1)
    assert ex.late_before is not None
    return [first, ex.late_before, ex]


def test_a_d0_that_took_the_d1_before_s_late_reply_is_no_repeat_check() -> None:
    steps = _steps(_late_d1_then_d0())
    for code in ("D0", "D1", "D0"):
        steps._own(code)  # base-s65: InvariantBroken R-4.4.5-10
    repeats = [o for o in steps.record.observations if o.check == "repeat"]
    assert len(repeats) == 2
    assert "late reply" in repeats[-1].late
    assert judge(repeats[-1]).checked == ()
    assert steps.last_d0 == HELD  # the late reply is no D0 to compare the next with


def test_a_d0_answered_in_its_own_window_still_breaches() -> None:
    exchanges = _late_d1_then_d0()
    exchanges[2].late_before = None  # a sensor never seen late: the reply is D0's own
    steps = _steps(exchanges)
    steps._own("D0")
    steps._own("D1")
    with pytest.raises(InvariantBroken, match="R-4.4.5-10"):
        steps._own("D0")


def test_the_judge_sets_a_late_taken_reply_aside() -> None:
    late = Observation("repeat", "0D0!", D1, previous=HELD, late="may be 0D1!'s late reply")
    assert judge(late).checked == ()
    own = Observation("repeat", "0D0!", D1, previous=HELD)
    assert judge(own).breach is not None
