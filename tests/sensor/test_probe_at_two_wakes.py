"""Silence to a one-shot probe counts only from a sensor shown to hear every break's wake-up.

A sensor that needs 110 ms after every second break only (fault slow-wake-every-other) never
heard ``aA$!`` or ``?I!`` sent after a break it woke from late, and answered their ``a!``
controls after the next breaks, which it woke from at once: R-4.3-04 and R-4.4.3-02 PASSed on
silence to probes it never heard (outside34's ``KNOWN_OPEN`` row, concurrent-three-digit-count
+ ident-pause + slow-wake-every-other). A silent probe's control now goes again after one more
break (:attr:`HeardProbe.recheck`): answered once and not the next time, the sensor wakes
differently from break to break and the silence is INCONCLUSIVE, whichever parity the probe
had.
"""

from __future__ import annotations

import pytest

from conformance.conduct import run_once
from conformance.emulator import sim_sensor
from conformance.sensor.session import SensorSession

PROBE_CASES = (
    "test_address_range or test_wildcard_with_other_commands or test_change_address "
    "or test_partial_command_dropped"
)
#: R-4.4.4-03's probe is the old address after a change; R-AppB-01's the cut aI!, whose
#: control (aI! in one piece) goes at two wakes the same way
RULES = ("R-4.3-04", "R-4.4.3-02", "R-4.4.4-03", "R-AppB-01")


def _verdicts(port: str, keyword: str) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in run_once(port, keyword=keyword)["requirements"]}


@pytest.mark.parametrize(
    "keyword",
    [
        PROBE_CASES,
        # one more break before them (the identification's own), so the other parity
        "test_identification or " + PROBE_CASES,
    ],
)
def test_silence_after_a_slow_wake_every_other_time_is_inconclusive(keyword):
    found = _verdicts("sim://?faults=slow-wake-every-other", keyword)
    assert [found[rid] for rid in RULES] == ["INCONCLUSIVE"] * len(RULES)


def test_the_clean_sensor_still_passes_both():
    found = _verdicts("sim://", PROBE_CASES)
    assert [found[rid] for rid in RULES] == ["PASS"] * len(RULES)


def test_the_recheck_goes_only_after_a_silent_probe_whose_control_was_answered():
    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    silent = sensor.heard_probe("9!")
    assert silent.recheck is not None and silent.recheck.answered and silent.listening
    answered = sensor.heard_probe("0I!")
    assert answered.probe.answered and answered.recheck is None
