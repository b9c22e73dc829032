"""Several DUTs on one port, live (issue 23, item 2): ``--address 0,1,3`` / ``--address all``
on ``sim://?sensors=...``, each sensor judged in its own folder, then the bus cases.

(i) A clean three-sensor bus: every sensor COMPLIANT with both bus cases PASSing, ``duts``
naming all three, ``?!`` never sent. (ii) The bus fault matrix: each bus fault on sensor 1 FAILs
exactly its requirements in sensor 1's folder, the bus case FAILing among them, and the clean
neighbours FAIL nothing. (iii) A duplicate address stops the run before anything is judged
(exit 4, only bus.json); a named address nothing answers at stops it with exit 5.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from rich.console import Console

from conformance.commands.bus import BUS_FILE, run_bus
from conformance.emulator import FAULTS
from conformance.run import RunOptions
from tests.support.paths import ROOT

SCHEMA = json.loads((ROOT / "conformance" / "schemas" / "verdicts-1.json").read_text("utf-8"))
BUS_CASES = (
    "testcases.sensor.test_bus::test_concurrent_kept_while_others_answer",
    "testcases.sensor.test_bus::test_silent_while_others_are_addressed",
)


def run(port: str, address: str, folder: Path) -> tuple[int, str]:
    """The main command's bus path in this process: its exit code and console text."""
    out = io.StringIO()
    options = RunOptions(port=port, address=address, report_dir=str(folder))
    return run_bus(options, Console(file=out, width=200)), out.getvalue()


def verdicts(folder: Path) -> dict[str, Any]:
    data = json.loads((folder / "verdicts.json").read_text(encoding="utf-8"))
    jsonschema.validate(data, SCHEMA)
    return data


def by_verdict(data: dict[str, Any], verdict: str) -> set[str]:
    return {r["id"] for r in data["requirements"] if r["verdict"] == verdict}


def bus_findings(data: dict[str, Any]) -> dict[tuple[str, str], str]:
    """(case, requirement) -> verdict of each bus case's finding."""
    return {
        (f["test"], r["id"]): f["verdict"]
        for r in data["requirements"]
        for f in r["findings"]
        if f["test"] in BUS_CASES
    }


@pytest.fixture(scope="module")
def clean_bus(tmp_path_factory) -> tuple[Path, int, str]:
    folder = tmp_path_factory.mktemp("bus") / "run"
    code, said = run("sim://?sensors=0,1,3", "all", folder)
    return folder, code, said


@pytest.mark.slow  # three whole runs; the default selection keeps the two-sensor fault run
def test_a_clean_bus_of_three_is_compliant_with_every_bus_case_judged(clean_bus):
    folder, code, said = clean_bus
    assert code == 0, said
    assert sorted(p.name for p in folder.iterdir()) == [
        BUS_FILE, "sensor-0", "sensor-1", "sensor-3"
    ]  # fmt: skip
    found = json.loads((folder / BUS_FILE).read_text(encoding="utf-8"))
    assert [s["address"] for s in found["sensors"]] == ["0", "1", "3"]
    assert found["duplicates"] == [] and found["probes"] >= 62  # a! at every address
    for a in "013":
        data = verdicts(folder / f"sensor-{a}")
        assert data["dut"]["address"] == a and f"SN000{'013'.index(a) + 1}" in data["dut"]["serial"]
        assert data["summary"]["verdict"] == "COMPLIANT" and not by_verdict(data, "FAIL")
        assert [d["address"] for d in data["duts"]] == ["0", "1", "3"]
        assert set(bus_findings(data).values()) == {"PASS"}, bus_findings(data)
        assert len(bus_findings(data)) == 2
        # what a shared line cannot show alone is said, not guessed
        assert {"R-4.4.3-01", "R-4.4.3-02", "R-4.3-03"} <= by_verdict(data, "INCONCLUSIVE")
        checked = {c for t in data["tests"] for c in t["preconditions"]}
        assert {"alone", "others"} <= checked  # the bus-only codes (test_preconditions.py)
    assert "sensors on the bus:" in said and said.count("· COMPLIANT ·") == 3


@pytest.mark.slow  # the three-sensor bus run above
def test_no_query_goes_onto_a_shared_bus(clean_bus):
    folder, _code, _said = clean_bus
    for a in "013":
        text = (folder / f"sensor-{a}" / "transcript.jsonl").read_text(encoding="utf-8")
        tool = [json.loads(line) for line in text.splitlines() if '"tool"' in line]
        sent = "".join(chr(e["wire"] & 0x7F) for e in tool if e.get("kind") == "char")
        assert "?" not in sent


#: Each bus fault (and the single-sensor fault the bus case catches as well), on sensor 1 of
#: a bus of two: its requirements, exactly.
BUS_MATRIX = (
    "aborts-on-foreign-reply",
    "answers-foreign-reply",
    "foreign-command-aborts-concurrent",
)
FAST = {"answers-foreign-reply"}  # the rest run with the other matrix rows (.ci/run)


@pytest.mark.parametrize(
    "fault", [pytest.param(f, marks=() if f in FAST else pytest.mark.matrix) for f in BUS_MATRIX]
)
def test_a_bus_fault_fails_exactly_its_requirements(fault, tmp_path):
    code, said = run(f"sim://?sensors=0,1:{fault}", "0,1", tmp_path)
    assert code == 1, said
    faulty, clean = verdicts(tmp_path / "sensor-1"), verdicts(tmp_path / "sensor-0")
    assert by_verdict(faulty, "FAIL") == set(FAULTS[fault].violates)
    assert "FAIL" in bus_findings(faulty).values()  # a bus case caught it
    assert not by_verdict(clean, "FAIL"), by_verdict(clean, "FAIL")
    assert set(bus_findings(clean).values()) == {"PASS"}


def test_every_bus_fault_is_in_the_bus_matrix():
    assert {n for n, f in FAULTS.items() if f.bus} <= set(BUS_MATRIX)


def test_a_duplicate_address_is_a_bus_fault_found_before_anything_is_judged(tmp_path, capsys):
    code, _said = run("sim://?sensors=0,0,3", "all", tmp_path / "all")
    assert code == 4
    assert sorted(p.name for p in (tmp_path / "all").iterdir()) == [BUS_FILE]
    found = json.loads((tmp_path / "all" / BUS_FILE).read_text(encoding="utf-8"))
    assert [d["address"] for d in found["duplicates"]] == ["0"]
    assert "two sensors answer at address '0'" in capsys.readouterr().err
    named, _ = run("sim://?sensors=3,0,0", "0,3", tmp_path / "named")
    assert named == 4 and not (tmp_path / "named" / "sensor-3").exists()


def test_a_named_sensor_that_does_not_answer_stops_the_run(tmp_path, capsys):
    code, _said = run("sim://?sensors=0,1", "0,1,5", tmp_path)
    assert code == 5
    assert "nothing answered a! at 5" in capsys.readouterr().err
    assert not (tmp_path / "sensor-0").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["--address", "0,0"],  # an address named twice
        ["--address", "0,1", "--port", "sim://?sensors=0,1", "--role", "recorder"],
        ["--address", "0,1", "--port", "sim://?sensors=0,1", "--baseline", "x"],
        ["--address", "0,1", "--port", "sim://?sensors=0,1:no-such-fault"],
    ],
)
def test_a_bus_run_that_cannot_work_is_a_usage_error(argv, tmp_path, capsys):
    from conformance.cli import main

    assert main([*argv, "--report-dir", str(tmp_path / "run")]) == 4
    assert capsys.readouterr().err.startswith("error: ")
    assert not (tmp_path / "run" / "sensor-0").exists()


@pytest.mark.slow  # a second whole run of one sensor
def test_judge_replays_one_sensor_of_the_bus_to_the_same_verdicts(clean_bus, tmp_path):
    """``judge sensor-1/`` repeats that sensor's run against its recording: the bus (from the
    run-options note) again, so no ?! and the same bus cases, to the same verdicts."""
    from conformance.cli import cmd_judge

    folder, _code, _said = clean_bus
    out = io.StringIO()
    code = cmd_judge(
        [str(folder / "sensor-1"), "--report-dir", str(tmp_path / "judged")],
        Console(file=out, width=200),
    )
    assert code == 0, out.getvalue()
    ran, judged = verdicts(folder / "sensor-1"), verdicts(tmp_path / "judged")
    assert {r["id"]: r["verdict"] for r in ran["requirements"]} == {
        r["id"]: r["verdict"] for r in judged["requirements"]
    }
    assert len(bus_findings(judged)) == 2


@pytest.mark.slow
def test_sensors_at_the_spare_and_foreign_addresses_are_left_alone(tmp_path):
    """The suite's own spare (9) and foreign (z) addresses taken by sensors of the bus: no
    probe meant for nobody reaches them, so every sensor stays COMPLIANT; the sweep through
    0-9 is left out where a sensor holds one of them, made where none does."""
    code, said = run("sim://?sensors=0,9,z", "all", tmp_path / "a")
    assert code == 0, said
    for a in "09z":
        assert verdicts(tmp_path / "a" / f"sensor-{a}")["summary"]["verdict"] == "COMPLIANT"
    code, said = run("sim://?sensors=y,z", "y,z", tmp_path / "b")
    assert code == 0, said
    assert "R-4.3-03" not in by_verdict(verdicts(tmp_path / "b" / "sensor-y"), "INCONCLUSIVE")


def test_all_finding_one_sensor_judges_it_alone(tmp_path):
    """One sensor found: its own folder, the whole suite with ?! (it is alone), no bus case."""
    code, said = run("sim://?address=5", "all", tmp_path)
    assert code == 0, said
    data = verdicts(tmp_path / "sensor-5")
    assert not bus_findings(data) and "duts" not in data
    assert by_verdict(data, "PASS") >= {"R-4.4.3-01", "R-4.3-03"}


def test_ctrl_c_after_one_sensor_leaves_the_rest_unbegun(tmp_path, monkeypatch):
    """A Ctrl-C recorded during sensor 1's run: its report stands, sensor 3's run is not
    begun, exit 2; and sensor 1's run began with the guard open again (the end of sensor 0's
    closed it). (The signal's own delivery is tests/e2e/test_interrupts.py's.)"""
    import conformance.conduct as conduct_module
    from conformance.interrupts import GUARD

    real = conduct_module.conduct
    closed_at_start: list[bool] = []

    def interrupted_after(options, **kw):
        closed_at_start.append(GUARD.closed)
        result = real(options, **kw)
        GUARD.requested = options.address == "1"  # as the SIGINT handler records it
        return result

    monkeypatch.setattr(conduct_module, "conduct", interrupted_after)
    GUARD.reset()
    GUARD.install()  # as the command line has it: a run's end closes it
    try:
        code, _said = run("sim://?sensors=0,1,3", "0,1,3", tmp_path)
    finally:
        GUARD.uninstall()
        GUARD.reset()
    assert code == 2
    assert closed_at_start == [False, False]  # sensor 1's run could still be interrupted
    assert (tmp_path / "sensor-1" / "verdicts.json").exists()
    assert not (tmp_path / "sensor-3").exists()


def test_ctrl_c_while_the_bus_is_looked_at_judges_nothing(tmp_path, monkeypatch, capsys):
    import conformance.sensor.bus_discovery as discovery
    from conformance.interrupts import GUARD

    real = discovery.discover_bus

    def interrupted(*args, **kw):
        found = real(*args, **kw)
        GUARD.requested = True
        return found

    monkeypatch.setattr(discovery, "discover_bus", interrupted)
    GUARD.reset()
    try:
        code, _said = run("sim://?sensors=0,1", "0,1", tmp_path)
    finally:
        GUARD.reset()
    assert code == 2 and sorted(p.name for p in tmp_path.iterdir()) == [BUS_FILE]
    assert "nothing judged" in capsys.readouterr().err


@pytest.mark.matrix
def test_three_faulty_sensors_each_fail_their_own_requirements_only(tmp_path):
    """Both bus faults and a single-sensor one, one per sensor of a bus of three: each
    sensor's folder FAILs exactly its own fault's requirements."""
    faults = {"0": "aborts-on-foreign-reply", "1": "answers-foreign-reply", "3": "wrong-crc"}
    port = "sim://?sensors=" + ",".join(f"{a}:{f}" for a, f in faults.items())
    code, said = run(port, "all", tmp_path)
    assert code == 1, said
    for a, fault in faults.items():
        failed = by_verdict(verdicts(tmp_path / f"sensor-{a}"), "FAIL")
        assert failed == set(FAULTS[fault].violates), (a, failed)


@pytest.mark.slow
def test_a_passive_judgement_of_the_bus_export_names_every_sensor(clean_bus, tmp_path):
    """Issue 23's acceptance: a capture of the live bus run (sensor 3's run: the round speaks
    to all three), judged passively, gives a report set per sensor, each naming all three,
    with every sensor's data rules judged from the wire."""
    from conformance.cli import cmd_judge
    from conformance.offline.export import export_main

    folder, _code, _said = clean_bus
    out = io.StringIO()
    capture = tmp_path / "bus.sr"
    console = Console(file=out, width=200)
    assert export_main([str(folder / "sensor-3"), "--to", "sr", "-o", str(capture)]) == 0
    judged = tmp_path / "judged"
    code = cmd_judge([str(capture), "--passive", "--report-dir", str(judged)], console)
    assert code in (0, 2), out.getvalue()  # 2: what a capture cannot show stays unjudged
    for address in "013":
        data = verdicts(judged / f"sensor-{address}")
        assert [d["address"] for d in data["duts"]] == ["0", "1", "3"]
        found = {r["id"]: r["verdict"] for r in data["requirements"]}
        assert found["R-4.4.8-01"] == found["R-4.4.8-02"] == "PASS", address
        assert "FAIL" not in found.values(), address
