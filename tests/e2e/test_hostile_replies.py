"""Hostile devices that answer like a sensor but mangle it (wrong parity, another address)
or vanish mid-run: findings or a clear error, never a hang or a traceback, and always the
report. Split from ``test_hostile_devices.py`` (same devices and helpers) so that the two
70-s runs (wrong parity here, NUL there) go to two workers side by side under
``--dist loadfile``."""

from __future__ import annotations

import pytest

from tests.e2e.test_hostile_devices import (
    CASES,
    WITH_FRAMING,
    bounded,
    findings_or_no_device,
    made_devices,
    mangled,
    no_traceback,
    polite,
    report,
    run_cli,
    seven_e1,
)

# Each test runs the CLI in a subprocess against a TCP device (10-70 s each on a busy machine).
pytestmark = pytest.mark.slow


@pytest.fixture
def device_factory():
    yield from made_devices()


def test_wrong_parity_is_a_finding(tmp_path, device_factory):
    odd = mangled(lambda text: bytes(b ^ 0x80 for b in seven_e1(text)))
    device = device_factory(odd)
    proc, took = run_cli(device.url, tmp_path, 180, "-k", WITH_FRAMING)
    no_traceback(proc)
    assert proc.returncode in (1, 5), proc.stdout + proc.stderr
    data = report(tmp_path)
    if proc.returncode == 1:
        failed = {r["id"] for r in data["requirements"] if r["verdict"] == "FAIL"}
        assert "R-4.1-02" in failed, failed
    bounded(took, device)


def test_answers_from_the_wrong_address_are_findings(tmp_path, device_factory):
    def other_address(command: str, _count: int) -> bytes | None:
        text = polite(command)
        return None if text is None else seven_e1("7" + text[1:] + "\r\n")

    device = device_factory(other_address)
    proc, took = run_cli(device.url, tmp_path, 120, "-k", CASES, "--address", "0")
    findings_or_no_device(proc, tmp_path, took)


def test_port_vanishing_mid_run_is_exit_3_with_the_report(tmp_path, device_factory):
    device = device_factory(mangled(seven_e1), vanish_after=5)  # after discovery
    proc, took = run_cli(device.url, tmp_path, 120, "-k", CASES)
    no_traceback(proc)
    assert proc.returncode == 3, proc.stdout + proc.stderr
    data = report(tmp_path)
    assert data["run"]["complete"] is False
    assert "failed during the run" in data["run"]["stop_reason"]
    assert took < 60
