"""``sdi12-conform calibrate``: the bench probe a user runs before a long run."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conformance.calibrate import RULES, calibrate_main
from conformance.emulator_server.process import EmulatorProcess


def calibrate(*args: str) -> tuple[int, str]:
    proc = subprocess.run(
        [sys.executable, "-m", "conformance.cli", "calibrate", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    text = proc.stdout + proc.stderr
    assert "Traceback" not in text, text
    return proc.returncode, text


@pytest.mark.realtime
def test_calibrate_behind_an_echoing_16ms_usb_adapter():
    """The README's example: echo found, breaks UART-timed (so the break rules are decided),
    a 16 ms latency timer leaves the response window and the gap undecided, and says so."""
    with EmulatorProcess("--echo", "--usb-latency", "16") as emulator:
        code, text = calibrate("--port", emulator.url, "--rounds", "4")
    assert code == 0, text
    assert "the interface echoes the tool" in text
    assert "UART-timed near thresholds" in text and "kernel" in text
    lines = {line.split()[0]: line for line in text.splitlines() if line.startswith("  R-")}
    assert set(lines) == {rule.rules for rule in RULES}, text
    assert "decided" in lines["R-7.0-03"] and "UART-timed" in lines["R-7.0-03"], text
    # every gap the probe measured lies in a batch or next to one: none decidable
    assert "INCONCLUSIVE" in lines["R-7.0-12/-01"] and "(0 of " in lines["R-7.0-12/-01"], text
    assert "a run here would use: measured ±" in text


@pytest.mark.realtime
def test_calibrate_without_echo_keeps_the_declared_floor():
    with EmulatorProcess() as emulator:
        code, text = calibrate("--port", emulator.url, "--rounds", "2")
    assert code == 0, text
    assert "no echo" in text and "declared floor 5.00 ms" in text, text


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["--port", "sim"], "virtual clock"),
        (["--port", "rfc2217://127.0.0.1:1", "--address", "00"], "0-9, A-Z, a-z"),
        (["--port", "rfc2217://127.0.0.1:1"], "cannot connect"),
        (["--port", "rfc2217://127.0.0.1:1", "--rounds", "0"], "--rounds"),
    ],
    ids=["sim", "bad-address", "no-server", "bad-rounds"],
)
def test_calibrate_usage_errors_exit_4(args, says):
    said: list[str] = []
    assert calibrate_main(args, said.append) == 4
    assert says in " ".join(said), said
