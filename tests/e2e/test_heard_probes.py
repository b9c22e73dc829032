"""Silence is evidence only from a sensor shown to be listening (issue 18).

One-off probes whose point is silence (foreign addresses, ``aA$!``, ``?I!``, the old address
after ``aAb!``) used to go out once, 9 ms after a break. A sensor that needs longer to wake
(a fault of R-7.0-05, judged there) never heard them, and its silence PASSed the rules the
probes are about, in the same run that FAILed R-7.0-05 for that slowness. Now each probe is
sent with the marking a one-shot ``a!`` was shown to need, and is followed by an ``a!`` control
sent the same way: silence counts only where the control was answered.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.conduct import run_once
from conformance.emulator import sim_sensor
from conformance.judges.exchanges import silent_while_listening
from conformance.sensor.session import HEARING_MARKINGS, HeardProbe, SensorSession
from conformance.verdicts import Verdict


def verdict(data: dict, rid: str) -> str:
    return next(r["verdict"] for r in data["requirements"] if r["id"] == rid)


def test_a_slow_waking_sensor_that_takes_a_bad_address_is_caught():
    """Before: aA$! 9 ms after the break went unheard by a sensor needing 20 ms, and
    R-4.3-04 PASSed ("refused '$'") although the sensor takes '$' when it hears it."""
    data = run_once(
        "sim://?faults=late-address-after-break,accepts-invalid-address",
        keyword="test_address_range",
    )
    assert verdict(data, "R-4.3-04") == "WARN"  # a MAY rule: broken, a WARN


def test_a_slow_waking_sensor_that_answers_foreign_addresses_is_caught():
    """Before: every foreign-address probe went unheard by a sensor that needs 110 ms to
    wake, and R-4.0-01 PASSed."""
    data = run_once(
        "sim://?faults=slow-wake,answers-foreign-address",
        keyword="test_foreign_addresses_are_ignored",
    )
    assert verdict(data, "R-4.0-01") == "FAIL"


def test_the_clean_sensor_is_heard_at_the_recorder_s_own_marking():
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    assert sensor.hearing_marking() == HEARING_MARKINGS[0]
    heard = sensor.heard_probe("9!")
    assert not heard.probe.answered and heard.listening
    assert not any("one-shot" in a for a in sensor.assumptions)


def test_a_sensor_deaf_to_every_one_shot_command_leaves_silence_unjudged():
    """A sensor that hears nothing within 250 ms of a break: no marking works, the probes'
    silence is INCONCLUSIVE "precondition not met", never a PASS."""
    bus, link, emulator = sim_sensor()
    emulator.behaviour = replace(emulator.behaviour, wake_delay=0.25)
    sensor = SensorSession(link, address="0")
    assert sensor.hearing_marking() is None
    assert any("not judged" in a for a in sensor.assumptions)
    probes = [sensor.heard_probe(f"{other}!") for other in "12"]
    assert all(p.control is None and not p.listening for p in probes)
    finding = silent_while_listening("R-4.0-01", probes, "another address")
    assert finding.verdict is Verdict.INCONCLUSIVE
    assert "precondition not met" in finding.detail


@pytest.mark.parametrize(
    "controls, want",
    [((True, True), "PASS"), ((False, True), "PASS"), ((False, False), "INCONCLUSIVE")],
)
def test_silence_counts_only_where_the_control_was_answered(controls, want):
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    silent = sensor.master.raw("9!", break_first=True)
    answered = sensor.master.raw("0!", break_first=True)
    unanswered = sensor.master.raw("8!", break_first=True)
    probes = [HeardProbe(silent, answered if ok else unanswered, 9e-3) for ok in controls]
    finding = silent_while_listening("R-4.0-01", probes, "another address")
    assert str(finding.verdict) == want
    if want == "PASS":
        assert finding.observed == 2 * sum(controls)
        assert ("set aside" in finding.detail) == (not all(controls))


def test_an_answer_to_a_probe_fails_whatever_its_control_did():
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    wrong = sensor.master.raw("0!", break_first=True)  # stands in for an answered probe
    silent = sensor.master.raw("8!", break_first=True)
    finding = silent_while_listening(
        "R-4.0-01", [HeardProbe(wrong, silent, 9e-3)], "another address"
    )
    assert finding.verdict is Verdict.FAIL
    assert finding.observed == 1 and finding.evidence


# -- partial and hidden devices: only total silence is "no device" (issue 18) ----------------
def test_a_sensor_that_wakes_only_on_long_breaks_is_judged_with_them():
    """Before: a sensor that takes only spacing of 30 ms or more as a break got exit 5, "no
    device answered"; now the tool tries longer breaks and goes on with the one it hears."""
    _, link, emulator = sim_sensor()
    emulator.behaviour = replace(emulator.behaviour, break_threshold=25e-3)
    sensor = SensorSession(link)
    sensor.discover()
    assert sensor.master.policy.break_duration == 30e-3
    assert sensor.identity is not None and sensor.ident_exchange.answered
    assert any("30 ms" in a for a in sensor.assumptions)


def test_a_sensor_that_answers_only_the_query_is_judged_on_what_it_does():
    """Before: a device answering ?! but not a! or aI! ended the run with exit 5 and nothing
    judged; now the run goes on (a! unanswered is then its case's FAIL)."""
    from conformance.emulator.faults import FaultSet
    from conformance.emulator.replies import ReplyKind

    class Mute(FaultSet):
        def rewrite(self, reply):  # a! and aI! unanswered, everything else as usual
            mute = (ReplyKind.ACKNOWLEDGE, ReplyKind.IDENTIFICATION)
            return None if reply.kind in mute else super().rewrite(reply)

    _, link, emulator = sim_sensor()
    emulator.faults = Mute(emulator.faults.faults, emulator.behaviour)
    sensor = SensorSession(link, address="0")
    sensor.discover()
    assert sensor.identity is None
    assert any("?! was answered" in a for a in sensor.assumptions)


def test_a_sensor_that_ignores_the_query_is_found_by_asking_each_address():
    """Seed 4158: a sensor at '1' that ignores ?! was called absent ("no device answered at
    address '0'"), the run INCOMPLETE with every rule undecided. Discovery now asks each
    address with a! once; the one that answers is judged, and ?!'s silence FAILs its rule."""
    data = run_once("sim://?faults=factory-address-not-zero,ignores-query")
    assert data["run"]["complete"], data["run"].get("stop_reason")
    assert verdict(data, "R-4.4.3-01") == "FAIL"
    assert verdict(data, "R-4.3-02") == "FAIL"
    assert data["dut"]["address"] == "1"
    assert any("only '1' answered" in a for a in data["dut"]["assumptions"]), data["dut"]


def test_an_address_asked_for_is_not_swapped_for_the_one_that_answers():
    """With --address given, the tool does not judge another device: it stops and names
    the address that answered a!."""
    from conformance.sensor.session import NoDeviceAnswered

    _, link, _ = sim_sensor(faults=("factory-address-not-zero", "ignores-query"))
    with pytest.raises(NoDeviceAnswered, match="answered at '1'.*--address 1"):
        SensorSession(link, address="7").discover()


def test_total_silence_is_still_no_device():
    from conformance.sensor.session import NoDeviceAnswered

    _, link, emulator = sim_sensor()
    emulator.behaviour = replace(emulator.behaviour, break_threshold=1.0)
    with pytest.raises(NoDeviceAnswered, match="100 ms"):
        SensorSession(link, address="0").discover()


def _maybe_collided(ex):
    """``ex`` as the engine records a probe whose break met a sensor character within the
    stamps' uncertainty (over RFC 2217, fault stray-after-line-end: a '#' ending 0.14..1.18
    ms after the break began, ±5 ms stamps)."""
    from conformance.tool_recorder.records import CONTENTION

    attempt = replace(ex.attempts[-1], reason=f"{CONTENTION} (1 characters during the command)")
    return replace(ex, attempts=[*ex.attempts[:-1], attempt])


def test_silence_to_a_probe_that_maybe_collided_is_no_evidence():
    """R-4.0-01 PASSed "stayed silent ... to 1 command(s)" on a foreign probe the sensor may
    not have heard (its break met the sensor's stray character); now it is set aside and,
    alone, leaves the rule INCONCLUSIVE, the evidence saying "maybe collided"."""
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    silent = _maybe_collided(sensor.master.raw("9!", break_first=True))
    answered = sensor.master.raw("0!", break_first=True)
    finding = silent_while_listening("R-4.0-01", [HeardProbe(silent, answered, 9e-3)], "another")
    assert finding.verdict is Verdict.INCONCLUSIVE, finding.detail  # PASS before
    assert silent.maybe_collided and not answered.maybe_collided
    assert "maybe collided" in finding.detail and "maybe collided" in " ".join(finding.evidence)
    clean = sensor.master.raw("8!", break_first=True)
    probes = [HeardProbe(silent, answered, 9e-3), HeardProbe(clean, answered, 9e-3)]
    finding = silent_while_listening("R-4.0-01", probes, "another")
    assert finding.verdict is Verdict.PASS and finding.observed == 2
    assert "1 probe(s) set aside (maybe collided" in finding.detail, finding.detail
