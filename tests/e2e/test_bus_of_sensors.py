"""Every sensor on the bus is a DUT (issue 23, item 1): a recording of three sensors
(addresses 0, 1 and 3: ``aI!`` each, interleaved ``aC!`` to each, then the D commands of each,
a break before each sensor's first) judged passively, as a monitor or a one-wire capture of
it would give it (origin ``bus`` everywhere: tests/support/bus_of_sensors.py).

(i) Three sensor folders, each with its data rules judged (the concurrent measurements are
not "interrupted" by the traffic to the other sensors), ``duts`` naming all three. (ii) A
faulty sensor 1 FAILs in its own folder only. (iii) A command to sensor 0 between its aC!
and its aD0! still sets that measurement aside. (iv) ``--address 3`` judges sensor 3's data.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from conformance.cli import main
from tests.support.bus_of_sensors import ADDRESSES, record, serial
from tests.support.paths import ROOT

SCHEMA = json.loads((ROOT / "conformance" / "schemas" / "verdicts-1.json").read_text("utf-8"))
DATA_RULE = "R-4.4.8-01"


def verdicts(folder: Path) -> dict[str, Any]:
    data = json.loads((folder / "verdicts.json").read_text(encoding="utf-8"))
    jsonschema.validate(data, SCHEMA)
    return data


def by_id(data: dict[str, Any]) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in data["requirements"]}


def failed(data: dict[str, Any]) -> set[str]:
    return {rid for rid, v in by_id(data).items() if v == "FAIL"}


def interrupted(data: dict[str, Any]) -> list[str]:
    return [n for n in data["dut"]["assumptions"] if "interrupted" in n]


@pytest.fixture(scope="module")
def clean_bus(tmp_path_factory) -> tuple[Path, int, str]:
    """The clean bus judged with both roles: its run folder, the exit code and the console."""
    import io

    from rich.console import Console

    from conformance.cli import cmd_judge

    tmp = tmp_path_factory.mktemp("bus")
    path = record(tmp / "recording")
    out = io.StringIO()
    code = cmd_judge(
        [str(path), "--role", "both", "--report-dir", str(tmp / "judged")],
        Console(file=out, width=1000),  # lines hold tmp paths: no wrap however long they are
    )
    return tmp / "judged", code, out.getvalue()


def test_each_sensor_of_the_bus_is_judged_in_its_own_folder(clean_bus):
    run, code, said = clean_bus
    assert sorted(p.name for p in run.iterdir() if p.is_dir()) == [
        "recorder", "sensor-0", "sensor-1", "sensor-3"
    ]  # fmt: skip
    assert code in (0, 2), said  # compliant, or incomplete (what one recording cannot show)
    for a in ADDRESSES:
        data = verdicts(run / f"sensor-{a}")
        assert data["run"]["role"] == "sensor" and data["dut"]["address"] == a
        assert serial(a) in data["dut"]["identification"]
        assert not failed(data), failed(data)
        assert by_id(data)[DATA_RULE] == "PASS"  # the concurrent data, judged
        assert by_id(data)["R-4.4.8-03"] == "PASS"  # all 20 announced values came
        assert not interrupted(data), interrupted(data)
        # every finding that names what it checked is about this sensor
        for r in data["requirements"]:
            for f in r["findings"]:
                if "checked: " in f["detail"]:
                    labels = f["detail"].split("checked: ", 1)[1].rstrip(")").split(", ")
                    assert all(x.removeprefix("reply to ")[:1] == a for x in labels), f
    assert not failed(verdicts(run / "recorder"))


def test_every_report_names_all_the_sensors_on_the_bus(clean_bus):
    run, _, _ = clean_bus
    for folder in ("sensor-0", "sensor-1", "sensor-3", "recorder"):
        duts = verdicts(run / folder)["duts"]
        assert [d["address"] for d in duts] == list(ADDRESSES)
        assert [d["serial"] for d in duts] == [serial(a) for a in ADDRESSES]
        assert all(d["model"] == "EMU001" and d["sdi12_version"] == "1.4" for d in duts)
    page = (run / "sensor-1" / "report.html").read_text(encoding="utf-8")
    assert "Other sensors on the bus" in page
    assert f"0: 014CONFORM EMU001100{serial('0')}" in page
    assert f"3: 314CONFORM EMU001100{serial('3')}" in page


def test_the_console_gives_one_line_per_sensor(clean_bus):
    run, _, said = clean_bus
    assert "3 sensors on the bus (0, 1, 3), each a DUT" in said
    lines = said.split("sensors on the bus:\n", 1)[1].splitlines()[: len(ADDRESSES)]
    for a, line in zip(ADDRESSES, lines, strict=True):
        verdict = verdicts(run / f"sensor-{a}")["summary"]["verdict"]
        assert line.split()[:2] == ["sensor", a], line
        assert serial(a) in line and verdict in line and str(run / f"sensor-{a}") in line


def test_a_faulty_sensor_fails_in_its_own_folder_only(tmp_path):
    """Sensor 1 sends every ASCII CRC off by one (after aCC!): R-4.4.12-05 FAILs in
    sensor-1/ alone, and the run exits 1."""
    path = record(tmp_path / "recording", faults={"1": ("wrong-crc",)}, code="CC")
    run = tmp_path / "judged"
    assert main(["judge", str(path), "--role", "sensor", "--report-dir", str(run)]) == 1
    assert failed(verdicts(run / "sensor-1")) == {"R-4.4.12-05"}
    assert by_id(verdicts(run / "sensor-1"))[DATA_RULE] == "PASS"
    for a in "03":
        data = verdicts(run / f"sensor-{a}")
        assert not failed(data), failed(data)
        assert by_id(data)["R-4.4.12-05"] == "PASS"  # their CRCs, judged and right
    assert not (run / "recorder").exists()


def test_a_command_to_the_sensor_itself_still_sets_its_measurement_aside(tmp_path):
    """0I! after 0C! and before 0D0! aborts sensor 0's measurement (R-4.4.7.1-01): its data
    rules are not judged on it (nothing else of sensor 0's to judge them on), the note
    counts that one, and sensors 1 and 3 are judged as on a clean bus."""
    path = record(tmp_path / "recording", meddle={"0": "0I!"})
    run = tmp_path / "judged"
    assert main(["judge", str(path), "--role", "sensor", "--report-dir", str(run)]) in (0, 2)
    zero = verdicts(run / "sensor-0")
    notes = interrupted(zero)
    assert len(notes) == 1 and notes[0].startswith("1 recorded measurement(s)"), notes
    assert by_id(zero)[DATA_RULE] == "INCONCLUSIVE"
    data_rule = next(r for r in zero["requirements"] if r["id"] == DATA_RULE)
    assert "not seen in the recording" in data_rule["findings"][0]["detail"]
    for a in "13":
        data = verdicts(run / f"sensor-{a}")
        assert by_id(data)[DATA_RULE] == "PASS" and not interrupted(data)


def test_address_judges_that_sensors_data_in_one_folder(tmp_path):
    """--address 3 narrows to sensor 3 (today's single layout) and judges its data rules."""
    path = record(tmp_path / "recording")
    run = tmp_path / "judged"
    code = main(["judge", str(path), "--role", "sensor", "--address", "3", "--report-dir",
                 str(run)])  # fmt: skip
    assert code in (0, 2)
    assert not any(p.is_dir() for p in run.iterdir())
    data = verdicts(run)
    assert data["dut"]["address"] == "3" and serial("3") in data["dut"]["identification"]
    assert by_id(data)[DATA_RULE] == "PASS" and by_id(data)["R-4.4.8-03"] == "PASS"
    assert not interrupted(data)
    assert [d["address"] for d in data["duts"]] == list(ADDRESSES)


def test_one_sensor_keeps_one_folder_with_itself_as_the_bus(tmp_path):
    """A recording of a single sensor keeps today's layout; ``duts`` lists that one."""
    path = record(tmp_path / "recording", "0")
    run = tmp_path / "judged"
    assert main(["judge", str(path), "--role", "sensor", "--report-dir", str(run)]) in (0, 2)
    assert not any(p.is_dir() for p in run.iterdir())
    data = verdicts(run)
    assert data["dut"]["address"] == "0" and by_id(data)[DATA_RULE] == "PASS"
    assert [d["address"] for d in data["duts"]] == ["0"]
