"""The C kit's pin adapter (conformance/kit/c/sdi12_kit_pin.h on the Arduino core): C firmware
that bit-bangs, built with cc and linked with c++ against the core. examples/c/pin_sensor.c
(tiny_sensor.c behind an edge interrupt and a bit-by-bit send) sends frames at its own bit
time, back to back, and is COMPLIANT with the bit rate judged; its twin -DBIT_US=800 (4 %
fast) FAILs exactly R-4.1-01, as the emulator's fast-baud fault. Compiled once per module."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance.conduct import run_once
from conformance.emulator import FAULTS
from conformance.kit.build import build_c_pin
from conformance.matrices.sensor_matrix import row_from
from tests.kit.conftest import C_EXAMPLES, c_compiler, play_sensor

DECLARATION = str(C_EXAMPLES / "tiny_sensor.toml")
SOURCES = [C_EXAMPLES / "pin_sensor.c", C_EXAMPLES / "tiny_sensor.c"]
TOLERANCE_US = 10
#: the twins by bit time: the example's 833 us and 4 % fast
BITS = {833: (), 800: ("BIT_US=800",)}


@pytest.fixture(scope="module")
def pin_sensor(kit_builds: Path) -> dict[int, Path]:
    """The example and its fast twin (skipped without a C and a C++ compiler)."""
    c_compiler()
    return {
        bit: build_c_pin(SOURCES, kit_builds / f"pin-sensor-{bit}", d) for bit, d in BITS.items()
    }


#: a break, then "0!" (the tool's 1200-baud frames)
ACKNOWLEDGE = ["break 0 12000", "char 20333 28667 30", "char 28667 37000 21"]


def frames_sent(binary: Path, events: list[str]) -> list[tuple[int, int, int]]:
    """The frames the firmware sent while the tool told it `events` (conftest.play_sensor)."""
    return play_sensor(binary, binary.name, events)[0]


@pytest.mark.parametrize("bit", sorted(BITS))
def test_the_frames_rebuilt_are_at_the_firmwares_bit_time(pin_sensor, bit):
    sent = frames_sent(pin_sensor[bit], ACKNOWLEDGE)
    assert [wire for _, _, wire in sent] == [0x30, 0x8D, 0x0A]  # "0" CR LF, even parity
    assert all(end - start == 10 * bit for start, end, _ in sent)  # ten of its own bits
    assert all(b[0] == a[1] for a, b in zip(sent, sent[1:], strict=False))  # back to back
    # its reply delay (10 ms) from the '!' as it heard it: the stop bit at its own bit time
    heard_end = 28667 + 1 + 10 * bit  # the edge handler's micros() costs 1 us
    assert abs(sent[0][0] - (heard_end + 10000)) <= TOLERANCE_US


@pytest.mark.slow  # a whole run; the default keeps the Arduino sketch's 4 %-slow twin
def test_the_fast_twin_fails_the_bit_rate(pin_sensor):
    data = run_once(
        f"exec:{pin_sensor[800]}", declaration=DECLARATION, keyword="test_reply_framing"
    )
    verdicts = {r["id"]: r for r in data["requirements"] if r["selected"]}
    assert verdicts["R-4.1-01"]["verdict"] == "FAIL"
    assert "8.00 ms" in verdicts["R-4.1-01"]["findings"][0]["detail"]
    assert [rid for rid, r in verdicts.items() if r["verdict"] == "FAIL"] == ["R-4.1-01"]


@pytest.mark.slow
def test_the_pin_sensor_is_compliant_with_its_bit_rate_judged(pin_sensor):
    data = run_once(f"exec:{pin_sensor[833]}", declaration=DECLARATION)
    counts = data["summary"]["counts"]
    assert data["summary"]["verdict"] == "COMPLIANT", counts
    assert counts["FAIL"] == counts["WARN"] == counts["ERROR"] == counts["INCONCLUSIVE"] == 0
    rate = {r["id"]: r for r in data["requirements"]}["R-4.1-01"]
    assert rate["verdict"] == "PASS"
    assert "8.330..8.330 ms" in rate["findings"][0]["detail"]
    assert counts["PASS"] >= 66  # 69 measured
    assert data["run"]["link"]["harness_stderr"].endswith("pin_sensor ready")


@pytest.mark.slow
def test_the_whole_suite_on_the_fast_twin_fails_what_fast_baud_does(pin_sensor):
    data = run_once(f"exec:{pin_sensor[800]}", declaration=DECLARATION)
    fault = FAULTS["fast-baud"]
    row = row_from("BIT_US=800", fault.violates, data, fault.inconclusive)
    assert row.exact, (row.missed, row.extra)
    assert row.failed == ("R-4.1-01",)
