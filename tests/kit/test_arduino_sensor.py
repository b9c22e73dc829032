"""The Arduino sensor sketch (examples/arduino/sdi12_sensor, with the TinySDI12 library: a
bit-banged send, an interrupt-driven receive) compiled with the kit: COMPLIANT, with the bit
rate judged (PASS: the link carries each frame's own length); each faulty twin (-D FAULT_...)
FAILs exactly the requirements of the emulator fault it copies, as a matrix row."""

from __future__ import annotations

import pytest

from conformance.cli import main
from conformance.conduct import run_once
from conformance.emulator import FAULTS
from conformance.exits import EXIT_NON_COMPLIANT, EXIT_OK, EXIT_USAGE
from conformance.matrices.sensor_matrix import row_from
from tests.kit.conftest import SENSOR, TINY_SDI12, build_dir

DECLARATION = str(SENSOR / "sdi12_sensor.toml")
#: the kit subcommand on the sensor sketch, as the README gives it
KIT_SENSOR = ("kit", "arduino", str(SENSOR), "--lib", str(TINY_SDI12))

#: each twin's -D flag and the emulator fault whose requirements it breaks
TWINS = {
    "FAULT_BAUD": "fast-baud",
    "FAULT_CRC": "wrong-crc",
    "FAULT_NO_SR": "no-service-request",
    "FAULT_SLOW_REPLY": "response-too-late",
}


def run_sketch(kit_build, *defines: str, **options) -> dict:
    binary = kit_build(SENSOR, (TINY_SDI12,), defines)
    return run_once(f"exec:{binary}", declaration=DECLARATION, **options)


@pytest.mark.slow
def test_the_sensor_sketch_is_compliant_with_its_bit_rate_judged(kit_build):
    data = run_sketch(kit_build)
    counts = data["summary"]["counts"]
    assert data["summary"]["verdict"] == "COMPLIANT", counts
    assert counts["FAIL"] == counts["WARN"] == counts["ERROR"] == counts["INCONCLUSIVE"] == 0
    verdicts = {r["id"]: r for r in data["requirements"]}
    assert sum(r["verdict"] == "PASS" for r in verdicts.values()) >= 65
    rate = verdicts["R-4.1-01"]
    assert rate["verdict"] == "PASS"
    assert "8.330..8.330 ms" in rate["findings"][0]["detail"]  # 833 us bits: 8330 us frames
    assert data["run"]["link"]["harness_stderr"].endswith("sdi12_sensor ready")


@pytest.mark.slow
@pytest.mark.parametrize("define", sorted(TWINS))
def test_a_faulty_twin_fails_exactly_its_requirements(kit_build, define):
    data = run_sketch(kit_build, define)
    fault = FAULTS[TWINS[define]]
    row = row_from(define, fault.violates, data, fault.inconclusive)
    assert row.exact, (row.missed, row.extra)
    assert row.failed == fault.violates
    assert data["summary"]["verdict"] == "NON-COMPLIANT"


@pytest.mark.slow  # a whole run and its verify; the 4 % slow twin keeps the rule in the inner loop
def test_a_sketch_4_percent_fast_fails_the_bit_rate(kit_builds, tmp_path):
    """Through the kit subcommand, as a user runs it: 800 us bits are 8.00 ms frames."""
    build, run = str(build_dir(kit_builds, SENSOR, ("FAULT_BAUD",))), str(tmp_path / "run")
    selected = ("-k", "test_reply_framing", "--declaration", DECLARATION, "--report-dir", run)
    code = main([*KIT_SENSOR, "-D", "FAULT_BAUD", "--build-dir", build, *selected])
    assert code == EXIT_NON_COMPLIANT
    text = (tmp_path / "run" / "verdicts.json").read_text()
    assert "frame length (ten bits): 8.00 ms" in text
    # judged again from the recording alone: the replay plays each frame at its own length
    assert main(["verify", run]) == EXIT_OK


def test_a_sketch_4_percent_slow_fails_the_bit_rate(kit_build):
    """867 us bits: 8.67 ms frames. The spacing of characters could be a gap; the length of
    each frame cannot, so the kit's link judges slow rates as well as fast ones."""
    data = run_sketch(kit_build, "TINY_SDI12_BIT_US=867", keyword="test_reply_framing")
    rate = {r["id"]: r for r in data["requirements"]}["R-4.1-01"]
    assert rate["verdict"] == "FAIL", rate
    assert "8.67 ms" in rate["findings"][0]["detail"]


def test_the_exact_sketch_passes_the_bit_rate(kit_build):
    data = run_sketch(kit_build, keyword="test_reply_framing")
    verdicts = {r["id"]: r["verdict"] for r in data["requirements"] if r["selected"]}
    assert verdicts["R-4.1-01"] == "PASS"
    assert data["summary"]["counts"]["FAIL"] == 0


@pytest.mark.usefixtures("kit_builds")  # skipped without a compiler
def test_a_sketch_that_does_not_compile_is_a_usage_error(tmp_path, capsys):
    sketch = tmp_path / "broken"
    sketch.mkdir()
    (sketch / "broken.ino").write_text("void setup() { undefined_call(); }\nvoid loop() {}\n")
    code = main(["kit", "arduino", str(sketch), "--build-dir", str(tmp_path / "b")])
    assert code == EXIT_USAGE
    err = capsys.readouterr().err
    assert "did not compile" in err and "undefined_call" in err and "broken.ino:1" in err


def test_build_only_names_the_port(kit_builds, capsys):
    built = build_dir(kit_builds, SENSOR)
    code = main([*KIT_SENSOR, "--build-only", "--build-dir", str(built)])
    assert code == EXIT_OK
    binary, port = capsys.readouterr().out.split("\n")[:2]
    assert port == f"exec:{binary}" and binary.startswith(str(built))
