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
from conformance.preconditions import (
    acknowledges,
    answered_control,
    listening,
    shows_listening,
    woke,
)
from conformance.protocol.timing import CHAR_TIME
from conformance.sensor.session import HeardProbe, SensorSession
from conformance.tool_recorder.records import CONTENTION, Exchange
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1
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


def _met_by_strays(ex, text: str):
    """``ex`` (an answered control) as the engine records it where sensor characters met
    its command and what came after them is ``text``: the rest of a stray burst read past
    the command's end (stamps uncertain by milliseconds), or a reply."""
    judged = ex.judged
    t = judged.command_end + 9e-3
    heard = []
    for c in text:
        heard.append(Event(EventKind.CHAR, DUT, t, t + CHAR_TIME, wire=to_wire_7e1(ord(c))))
        t += CHAR_TIME
    attempt = replace(
        judged, reply_events=heard, reason=f"{CONTENTION} (1 characters during the command)"
    )
    return replace(ex, attempts=[attempt])


@pytest.mark.parametrize("rid", ["R-7.0-03", "R-7.0-14", "R-AppB-01"])
def test_a_control_answered_only_by_what_met_it_shows_no_listening(rid):
    """A control whose own attempt maybe collided counted as answered whatever came back:
    the "reply" may be the stray characters that met it, so silence to the probe PASSed
    on a sensor never shown listening. Now such a control shows listening only with a
    valid reply to it ('0<CR><LF>' to 0!); '##' or another command's reply does not."""
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    control = sensor.master.raw("0!", break_first=True)
    probe = sensor.master.raw("1!", break_first=True)
    assert control.answered and not probe.answered
    for text in ("##", "0+1.23\r\n", "1\r\n"):
        stray = _met_by_strays(control, text)
        assert stray.maybe_collided and stray.answered
        assert not shows_listening(stray), text
        unmet = answered_control([stray], "to the probe")
        assert unmet is not None and unmet.code == "listening", text  # None before
        assert not HeardProbe(probe, stray, 9e-3).listening, text  # True before
        found = silent(rid, [probe], "it was asleep", baseline=stray)
        assert found.verdict is Verdict.INCONCLUSIVE, (text, found.detail)  # PASS before
        assert "maybe collided" in found.detail, found.detail
        heard = listening([HeardProbe(probe, stray, 9e-3)])
        assert heard is not None and "answered none" in heard.detail, heard.detail
    # its valid reply still shows the sensor listening, whatever met the command
    valid = _met_by_strays(control, "0\r\n")
    assert valid.maybe_collided and shows_listening(valid)
    assert answered_control([valid], "to the probe") is None
    assert HeardProbe(probe, valid, 9e-3).listening
    assert silent(rid, [probe], "it was asleep", baseline=valid).verdict is Verdict.PASS
    # a control that met nothing: as before
    assert shows_listening(control) and answered_control([control], "to the probe") is None


@pytest.mark.parametrize("rid", ["R-7.0-14", "R-7.0-15", "R-7.0-16"])
def test_a_wake_up_answered_only_by_what_met_it_shows_no_sensor_awake(rid):
    """preconditions.woke (the wake-up a! of R-7.0-14/-15/-16) took any answer as the sensor
    shown awake, even where the wake-up's own attempt maybe collided and what came after
    may be the rest of the stray characters: the probes' silence was then judged. Now, as
    for the controls (shows_listening), such a wake-up counts only with a valid reply."""
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    wake = sensor.master.transact("0!", force_break=True)
    assert woke([wake]) is None
    for text in ("##", "0+1.23\r\n", "1\r\n"):
        stray = _met_by_strays(wake, text)
        unmet = woke([stray])
        assert unmet is not None and unmet.code == "awake", (rid, text)  # None before
        assert "1 answer(s) set aside" in unmet.detail, unmet.detail
        assert woke([stray, wake]) is None  # another wake-up answered cleanly: awake
    assert woke([_met_by_strays(wake, "0\r\n")]) is None  # its valid reply: awake


@pytest.mark.parametrize("rid", ["R-4.3-04", "R-7.0-04", "R-7.0-05", "R-7.0-07", "R-4.4.4-01"])
def test_an_a_probe_answered_only_by_what_met_it_shows_no_acknowledgement(rid):
    """preconditions.acknowledges took any answered a! among the probes as the sensor
    answering a! at all; one whose own attempt maybe collided may have been answered by the
    rest of the characters that met it. It counts now only with a valid reply, and
    SensorSession.acknowledgement sends its a! control for it (it sent none before)."""
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    probe = sensor.master.raw("0!", break_first=True)
    assert acknowledges([probe], False, "0") is None
    for text in ("##", "0+1.23\r\n", "1\r\n"):
        stray = _met_by_strays(probe, text)
        unmet = acknowledges([stray], False, "0")
        assert unmet is not None and unmet.code == "listening", (rid, text)  # None before
        assert "1 answer(s) set aside" in unmet.detail, unmet.detail
        assert acknowledges([stray], True, "0") is None  # an a! answered elsewhere: as before
        sensor.master.acknowledged.discard("0")
        controls = sensor.acknowledgement([stray])
        assert len(controls) == 1 and controls[0].answered, text  # [] before
    valid = _met_by_strays(probe, "0\r\n")
    assert acknowledges([valid], False, "0") is None
    sensor.master.acknowledged.discard("0")
    assert sensor.acknowledgement([valid]) == []
