"""R-7.0-03/-04's sleep sends its foreign command without a break only behind a control
(issue 22, eff10): the run's wire must show the sensor answering its ``a!`` sent without a
break while awake. a11164e sent it without a break always, and CI's combination row
never-standby + no-follow-up-without-break caught a false PASS: a sensor deaf to every
command without a break heard neither the foreign command nor the ``a!`` check, and that
silence was taken as standby. Where the control is missing (a run that never showed it, or a
sensor that does not answer such an ``a!``) the 13 ms break and 50 ms of marking go first,
as before.

``_with_control`` makes what a whole run made long before the timing cases (at t=79.8 s of a
real one): a wake-up, then ``a!`` without a break right after the reply."""

from __future__ import annotations

import pytest

from conformance.sensor.session import SensorSession
from conformance.transcript import TOOL, EventKind, decode_7e1
from conformance.verdicts import Verdict
from testcases.sensor.test_7_timing import _asleep, unbroken_acknowledge_answered
from testcases.sensor.test_7_timing import test_break_just_over_12ms_wakes as wake_case
from testcases.sensor.test_7_timing import test_short_spacing_is_not_a_break as spacing_case
from tests.support.case_verdicts import case_verdict, sim_session

PAIR = "never-standby,no-follow-up-without-break"


def _with_control(session: SensorSession) -> SensorSession:
    session.master.transact(f"{session.address}!", force_break=True)
    session.master.raw(f"{session.address}!", break_first=False)
    return session


def _foreign_broken(session: SensorSession) -> bool:
    """Whether the last foreign command on the wire followed a break directly."""
    wire = [e for e in session.link.transcript.events if e.kind is not EventKind.NOTE]
    foreign = f"{session.foreign_address()}!"
    for i in range(len(wire) - 2, 0, -1):
        pair = wire[i : i + 2]
        if all(e.origin == TOOL for e in pair) and decode_7e1(pair) == foreign:
            return wire[i - 1].kind is EventKind.BREAK
    raise AssertionError("no foreign command on the wire")


def test_with_the_control_shown_the_foreign_command_goes_without_a_break():
    session = _with_control(sim_session())
    _asleep(session)
    assert not _foreign_broken(session)


@pytest.mark.parametrize("faults", ["", "no-follow-up-without-break", PAIR])
def test_without_the_control_the_break_goes_first_as_before(faults):
    session = sim_session(faults)  # discovery only: no a! answered without a break yet
    _asleep(session)
    assert _foreign_broken(session)


@pytest.mark.parametrize("faults", ["no-follow-up-without-break", PAIR])
def test_a_sensor_deaf_without_a_break_never_shows_the_control(faults):
    session = _with_control(sim_session(faults))
    _asleep(session)
    assert _foreign_broken(session)


@pytest.mark.parametrize(
    ("faults", "case_fn", "rule", "expected"),
    [
        # the false PASS of a11164e: never sleeps, and deaf to every command without a break
        (PAIR, spacing_case, "R-7.0-03", Verdict.INCONCLUSIVE),
        (PAIR, wake_case, "R-7.0-04", Verdict.INCONCLUSIVE),
        ("never-standby", spacing_case, "R-7.0-03", Verdict.INCONCLUSIVE),
        ("never-standby", wake_case, "R-7.0-04", Verdict.INCONCLUSIVE),
        ("no-follow-up-without-break", spacing_case, "R-7.0-03", Verdict.PASS),
        ("no-follow-up-without-break", wake_case, "R-7.0-04", Verdict.PASS),
        # sleeps by the foreign command or by the marking alone: either route still works
        ("standby-ignored", spacing_case, "R-7.0-03", Verdict.PASS),
        ("stays-awake-after-foreign", wake_case, "R-7.0-04", Verdict.PASS),
        ("wakes-on-short-spacing", spacing_case, "R-7.0-03", Verdict.FAIL),
        ("ignores-short-breaks", wake_case, "R-7.0-04", Verdict.FAIL),
        ("", spacing_case, "R-7.0-03", Verdict.PASS),
        ("", wake_case, "R-7.0-04", Verdict.PASS),
    ],
)
def test_r_7_0_03_04_verdicts_after_a_run_showed_the_control(faults, case_fn, rule, expected):
    """The verdicts the fault matrix declares, with the control on the wire before the case
    (with it the clean sensor's foreign command goes without a break)."""
    assert case_verdict(_with_control(sim_session(faults)), case_fn, rule) is expected


def test_the_control_needs_the_reply_to_the_unbroken_a():
    """The pure look over the transcript: an ``a!`` after the sensor's reply that drew
    ``a<CR><LF>`` counts; the same ``a!`` after a break, or unanswered, does not."""
    shown = _with_control(sim_session())
    assert unbroken_acknowledge_answered(shown.link.transcript.events, "0", 30e-3)
    broken = sim_session()
    broken.master.transact("0!", force_break=True)
    broken.master.transact("0!", force_break=True)
    assert not unbroken_acknowledge_answered(broken.link.transcript.events, "0", 30e-3)
    deaf = _with_control(sim_session("no-follow-up-without-break"))
    assert not unbroken_acknowledge_answered(deaf.link.transcript.events, "0", 30e-3)
