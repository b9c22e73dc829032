"""A bus of emulators served in real time over RFC 2217 (issue 23, item 2, on a real-time
link): ``sdi12-conform emulate --sensors ...`` in its own process, the CLI's ``--address all``
in another, as a user with a USB interface on a multi-drop line runs it.

(i) Three sensors, sensor 1 with a bus fault (``answers-foreign-reply``), behind an echoing
interface with a 16 ms USB latency timer (an FTDI cable): discovery finds all three over
RFC 2217 without ``?!``, sensor 1 FAILs exactly its fault's requirements, the other two FAIL
nothing and PASS both bus cases. Only the bus cases run (``-k test_bus``): about 12 s of bus
time per sensor. (ii) Two sensors at one address (``0,0,3``): exit 4 with ``bus.json`` alone,
naming address 0, before anything is judged.

The two runs go side by side (they mostly wait on their 1200-baud lines). On a machine too
busy for the served line to keep real time a verdict off what the fault makes is the host's
doing: the test skips with the line's measured lateness, never passes or fails on it.
"""

from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest

from conformance.commands.bus import BUS_FILE
from conformance.emulator import FAULTS
from conformance.emulator_server.process import EmulatorProcess
from tests.e2e.test_live_bus import BUS_CASES, bus_findings, by_verdict, verdicts
from tests.support.served_timing import fail_unless_too_busy

pytestmark = [pytest.mark.realtime, pytest.mark.slow]

FAULT = "answers-foreign-reply"
#: name -> (emulate options, the CLI's options after --port)
RUNS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "faulty": (
        ("--sensors", f"0,1:{FAULT},3", "--echo", "--usb-latency", "16"),
        ("--address", "all", "-k", "test_bus"),
    ),
    "duplicate": (("--sensors", "0,0,3"), ("--address", "all")),
}


@dataclass
class Served:
    """One bus run: the CLI's exit code and output, the server's first line, and how far
    (s) the served line fell behind its schedule over the run's connections."""

    code: int
    text: str
    serving: str
    late: float | None
    folder: Path


def _serve_and_run(name: str, folder: Path) -> Served:
    serve, tool = RUNS[name]
    emulator = EmulatorProcess(*serve)
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "conformance.cli", "--port", emulator.url,
             "--report-dir", str(folder), *tool],
            capture_output=True, text=True, timeout=240,
        )  # fmt: skip
        late = emulator.worst_lateness(connections=None)
    finally:
        emulator.stop()
    return Served(proc.returncode, proc.stdout + proc.stderr, emulator.log[0], late, folder)


@pytest.fixture(scope="module")
def served(tmp_path_factory) -> dict[str, Served]:
    base = tmp_path_factory.mktemp("served-bus")
    with ThreadPoolExecutor(len(RUNS)) as pool:
        futures = {name: pool.submit(_serve_and_run, name, base / name) for name in RUNS}
        return {name: f.result() for name, f in futures.items()}


def _unless_too_busy(run: Served, wrong: list[str]) -> None:
    """Fail on what the run got wrong, unless the served line could not keep real time."""
    fail_unless_too_busy(run.late, "; ".join(map(str, wrong)) if wrong else "", run.text)


def test_discovery_over_rfc2217_finds_every_served_sensor(served):
    run = served["faulty"]
    assert "bus of 3 reference sensors" in run.serving, run.serving
    found = json.loads((run.folder / BUS_FILE).read_text(encoding="utf-8"))
    addresses = [s["address"] for s in found["sensors"]]
    _unless_too_busy(run, [] if addresses == ["0", "1", "3"] else [f"found {addresses}"])
    assert found["duplicates"] == [] and found["probes"] >= 62  # a! at every address
    for n, a in enumerate("013", start=1):
        assert f"SN000{n}" in (found["sensors"][n - 1]["identification"] or "")
        data = verdicts(run.folder / f"sensor-{a}")
        assert data["run"]["link"]["kind"] == "rfc2217"
        assert data["run"]["link"]["bench"]["echo"] is True  # found by the link itself
        assert [d["address"] for d in data["duts"]] == ["0", "1", "3"]
        tool = (run.folder / f"sensor-{a}" / "transcript.jsonl").read_text(encoding="utf-8")
        sent = [json.loads(line) for line in tool.splitlines() if '"tool"' in line]
        assert "?" not in "".join(chr(e["wire"] & 0x7F) for e in sent if e.get("kind") == "char")


def test_the_faulty_sensor_fails_exactly_its_requirement_and_no_other_fails(served):
    run = served["faulty"]
    wrong: list[str] = []
    faulty = verdicts(run.folder / "sensor-1")
    if by_verdict(faulty, "FAIL") != set(FAULTS[FAULT].violates):
        wrong.append(f"sensor 1 FAILs {sorted(by_verdict(faulty, 'FAIL'))}")
    for a in "03":
        clean = verdicts(run.folder / f"sensor-{a}")
        findings = bus_findings(clean)
        if set(findings.values()) != {"PASS"} or len(findings) != len(BUS_CASES):
            wrong.append(f"sensor {a}: bus cases {findings}")
        if by_verdict(clean, "FAIL"):
            wrong.append(f"sensor {a} FAILs {sorted(by_verdict(clean, 'FAIL'))}")
    _unless_too_busy(run, wrong)
    assert "FAIL" in bus_findings(faulty).values()  # a bus case caught it
    assert run.code == 1, run.text
    assert run.text.count("· COMPLIANT ·") == 2 and "· NON-COMPLIANT ·" in run.text


def test_a_duplicate_address_served_exits_4_before_anything_is_judged(served):
    run = served["duplicate"]
    assert run.code == 4, run.text
    assert sorted(p.name for p in run.folder.iterdir()) == [BUS_FILE]
    found = json.loads((run.folder / BUS_FILE).read_text(encoding="utf-8"))
    assert [d["address"] for d in found["duplicates"]] == ["0"], found
    assert "two sensors answer at address '0'" in run.text
