"""R-5.3-01 judges HA and HB one after the other; whether the sensor hears one-off commands
after a break is the sensor's, checked per measurement. It used to void the whole rule: a
sensor whose HA lost its values after a break FAILed there, and then HB's unheard foreign
command dropped that FAIL, leaving R-5.3-01 INCONCLUSIVE on a device that plainly broke it."""

from __future__ import annotations

from dataclasses import replace

from conformance.conduct import run_once
from conformance.emulator.sensor import SensorEmulator
from conformance.sensor.session import SensorSession


def test_an_unheard_probe_while_hb_ran_keeps_the_fail_ha_earned(monkeypatch):
    breaking = SensorEmulator.on_break

    def on_break(self, start: float, end: float) -> None:
        run = self._run
        only_ha = run is not None and run.command.text().endswith("HA!")
        saved = self.behaviour
        self.behaviour = replace(saved, break_aborts_concurrent=only_ha)
        try:
            breaking(self, start, end)
        finally:
            self.behaviour = saved

    monkeypatch.setattr(SensorEmulator, "on_break", on_break)
    monkeypatch.setattr(SensorSession, "hearing_marking", lambda self: None)
    data = run_once("sim://", keyword="test_high_volume_is_concurrent")
    row = next(r for r in data["requirements"] if r["id"] == "R-5.3-01")
    assert row["verdict"] == "FAIL", row
    details = [f["detail"] for f in row["findings"]]
    assert any("aHA! delivered" in d for d in details), details
    assert any("precondition not met: listening" in d for d in details), details
