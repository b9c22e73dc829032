"""Being a good guest on real hardware (design.md 7): an address change is undone even when the
run is interrupted in the middle of it, and Ctrl-C still writes the partial report and
exits 2."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from dataclasses import replace

import pytest

from conformance.case import Case
from conformance.emulator_server.process import EmulatorProcess
from conformance.links.factory import open_real_link
from conformance.ports import open_sim, parse_sim
from conformance.results import CaseRecord
from conformance.sensor.address_change import AddressChanger
from conformance.sensor.session import SensorSession
from conformance.tool_recorder.engine import ToolRecorder
from testcases.sensor.test_4_4_basic import test_change_address as change_address_case


@pytest.fixture
def sim_sensor():
    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session, opened.devices[0]


def _interrupt_once_the_change_took(monkeypatch) -> list[str]:
    """Ctrl-C arrives while the tool polls the sensor at its new address."""
    seen: list[str] = []

    def interrupted(self, outcome) -> None:
        seen.append(self.current)
        raise KeyboardInterrupt

    monkeypatch.setattr(AddressChanger, "_await_answer", interrupted)
    return seen


def test_change_address_case_restores_the_address_on_ctrl_c(sim_sensor, monkeypatch):
    session, emulator = sim_sensor
    original = emulator.address
    seen = _interrupt_once_the_change_took(monkeypatch)
    record = CaseRecord("test_change_address", "test_change_address", ("R-4.4.4-01",))
    with pytest.raises(KeyboardInterrupt):
        change_address_case(session, Case(record))
    assert seen and seen[0] != original  # the interrupt came while the sensor was moved
    assert emulator.address == original
    assert session.address_notes[-1].startswith(f"address restored to '{original}'")


def test_address_sweep_restores_the_address_on_ctrl_c(sim_sensor, monkeypatch):
    session, emulator = sim_sensor
    original = emulator.address
    _interrupt_once_the_change_took(monkeypatch)
    with pytest.raises(KeyboardInterrupt):
        session.address_sweep("0123456789")
    assert emulator.address == original
    assert "restored" in session.address_notes[-1]


def test_a_failed_restore_is_reported_not_hidden(sim_sensor):
    """If the sensor cannot be found at its address again, the note says so in capitals."""
    session, emulator = sim_sensor
    changer = AddressChanger(session.master, session.address)
    changer.change(session.spare_address(), wait_for_answer=False)
    emulator.profile = replace(emulator.profile, address_settable=False)
    note = changer.restore()
    assert changer.restored is False and note.startswith("COULD NOT restore")


@pytest.mark.realtime
def test_ctrl_c_writes_the_partial_report_and_exits_2(tmp_path):
    """SIGINT to the CLI mid-run (over RFC 2217, so the run takes real time)."""
    emulator = EmulatorProcess()
    try:
        cli = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "conformance.cli",
                "--port",
                emulator.url,
                "--report-dir",
                str(tmp_path),
                "-k",
                "test_address_range or test_parameter_metadata",
                "--plan",  # the interrupt is for the run itself (planning: test_plan.py)
                "never",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        time.sleep(4.0)  # pytest start-up, discovery, and into the address sweep
        cli.send_signal(signal.SIGINT)
        out, _ = cli.communicate(timeout=60)
        assert cli.returncode == 2, out
        assert "Traceback" not in out, out
        data = json.loads((tmp_path / "verdicts.json").read_text())
        assert data["run"]["complete"] is False
        assert data["summary"]["verdict"] in ("INCOMPLETE", "NON-COMPLIANT")
        assert all("COULD NOT" not in note for note in data["dut"]["address_notes"])
        assert (tmp_path / "report.html").exists()
        # the sensor is where it was found: it answers at address 0
        link = open_real_link(emulator.url)
        try:
            assert ToolRecorder(link).acknowledge("0").answered
        finally:
            link.close()
    finally:
        emulator.stop()
