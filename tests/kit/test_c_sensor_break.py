"""The C kit's sensor adapter plans a break (``SDI12_BRK``: the harness protocol's ``brk``
from a sensor, docs/harness-protocol.md): the tool puts it on the line as the sensor's, tells
it back as ``break S E``, which the adapter hands to ``on_sent`` (the planned one went), not
to ``on_break`` (the sensor would take its own break for the recorder's and start over)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from conformance.harness.device import open_sensor_harness
from conformance.kit import C_DIR
from conformance.sim.bus import SENSOR_BREAK
from conformance.transcript import DUT, EventKind
from tests.kit.conftest import c_compiler

FIRMWARE = Path(__file__).parent / "firmware"


@pytest.fixture(scope="module")
def brk_sensor(tmp_path_factory: pytest.TempPathFactory) -> Path:
    binary = tmp_path_factory.mktemp("c-brk") / "brk-sensor"
    command = [c_compiler(), "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", f"-I{C_DIR}"]
    subprocess.run(
        [*command, "-o", str(binary), str(FIRMWARE / "brk_sensor.c")],
        check=True,
        capture_output=True,
    )
    return binary


def test_a_c_sensor_holds_the_line_spacing_then_replies(brk_sensor):
    link = open_sensor_harness(f"exec:{brk_sensor}")
    try:
        link.send_break(0.0125)
        link.wait_until(link.now() + 0.009)
        end = link.write(b"0!")[-1].end  # both of even weight already (7E1)
        got = link.receive(end + 0.1)
        stderr = link.harness_stderr() or ""
    finally:
        link.close()
    breaks = [e for e in link.transcript.events if e.kind is EventKind.BREAK and e.origin == DUT]
    assert len(breaks) == 1 and breaks[0].text == SENSOR_BREAK
    assert breaks[0].start == pytest.approx(end, abs=1e-6)
    assert breaks[0].duration == pytest.approx(0.0121, abs=1e-6)
    assert [e.wire & 0x7F for e in got] == [0x30, 0x0D, 0x0A]
    assert got[0].start == pytest.approx(breaks[0].end + 0.0084, abs=1e-6)
    # its own break went to on_sent: on_break heard the tool's break alone
    assert stderr.count("break ") == 1, stderr
    assert f"sent {round(breaks[0].start * 1e6)} {round(breaks[0].end * 1e6)}" in stderr
