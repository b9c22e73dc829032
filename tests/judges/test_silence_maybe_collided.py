"""Silence to a standby or short-pulse probe that maybe collided is no evidence (R-7.0-03,
R-7.0-14, R-7.0-15): the ninth truth round (be80803) set such probes aside in the foreign-address
and ?I! probes (silent_while_listening); judge.silent, which the standby and short-pulse cases
call, counted their silence as a PASS."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.conduct import run_once
from conformance.emulator import sim_sensor
from conformance.judges.exchanges import silent
from conformance.sensor.session import SensorSession
from conformance.tool_recorder.records import CONTENTION, Exchange
from conformance.verdicts import Verdict


def _maybe_collided(ex):
    """``ex`` as the engine records a probe whose break met a sensor character within the
    stamps' uncertainty (RFC 2217, fault stray-after-line-end, ±5 ms stamps)."""
    attempt = replace(ex.attempts[-1], reason=f"{CONTENTION} (1 characters during the command)")
    return replace(ex, attempts=[*ex.attempts[:-1], attempt])


@pytest.mark.parametrize("rid", ["R-7.0-03", "R-7.0-14", "R-7.0-15"])
def test_silence_that_maybe_collided_is_set_aside(rid):
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    probe = _maybe_collided(sensor.master.raw("1!", break_first=True))
    control = sensor.master.raw("0!", break_first=True)
    assert probe.maybe_collided and not probe.answered and control.answered
    alone = silent(rid, [probe], "it was asleep", baseline=control)
    assert alone.verdict is Verdict.INCONCLUSIVE, alone.detail  # PASS before
    assert "maybe collided" in alone.detail and "maybe collided" in " ".join(alone.evidence)
    clean = sensor.master.raw("2!", break_first=True)
    both = silent(rid, [probe, clean], "it was asleep", baseline=control)
    assert both.verdict is Verdict.PASS and both.observed == 1, both.detail
    assert "1 command(s) set aside (maybe collided" in both.detail


def _verdict(data: dict, rid: str) -> str:
    return next(r["verdict"] for r in data["requirements"] if r["id"] == rid)


@pytest.mark.parametrize(
    "rid, keyword",
    [
        ("R-7.0-03", "test_short_spacing_is_not_a_break"),
        ("R-7.0-14", "test_standby_after_foreign_command"),
        ("R-7.0-15", "test_standby_after_100ms"),
    ],
)
def test_the_standby_cases_leave_silence_that_maybe_collided_undecided(monkeypatch, rid, keyword):
    """The sim's stamps are exact, so no probe maybe collides there: every silent exchange is
    made one here, and the cases that PASS on the clean sensor are INCONCLUSIVE."""
    assert _verdict(run_once("sim://", keyword=keyword), rid) == "PASS"
    monkeypatch.setattr(Exchange, "maybe_collided", property(lambda ex: not ex.answered))
    assert _verdict(run_once("sim://", keyword=keyword), rid) == "INCONCLUSIVE"
