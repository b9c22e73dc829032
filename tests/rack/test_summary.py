"""The rack's own outputs over hand-made worker results: the worst exit status, rack.json,
junit.xml with one suite per DUT, index.html, and where a DUT's folder goes."""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest

from conformance.exits import (
    EXIT_COMPLIANT,
    EXIT_INCOMPLETE,
    EXIT_INTERNAL,
    EXIT_NO_DEVICE,
    EXIT_NON_COMPLIANT,
    EXIT_USAGE,
)
from conformance.rack.index_html import write_index
from conformance.rack.junit import write_junit
from conformance.rack.run import name_by_serial, place_folder
from conformance.rack.spec import Dut
from conformance.rack.summary import WORST_FIRST, dut_row, rack_document, worst

CODES = (EXIT_COMPLIANT, EXIT_NON_COMPLIANT, EXIT_INCOMPLETE, EXIT_INTERNAL, EXIT_USAGE,
         EXIT_NO_DEVICE)  # fmt: skip


def test_the_worst_order_holds_every_exit_status_once():
    assert sorted(WORST_FIRST) == sorted(CODES)
    assert WORST_FIRST[0] == EXIT_INTERNAL and WORST_FIRST[-1] == EXIT_COMPLIANT


@pytest.mark.parametrize("pair", list(itertools.combinations(CODES, 2)))
def test_the_rack_exits_with_its_worst_dut(pair):
    a, b = pair
    expected = a if WORST_FIRST.index(a) < WORST_FIRST.index(b) else b
    assert worst([a, b]) == worst([b, a]) == expected
    assert worst([a, b, EXIT_COMPLIANT]) == expected


def test_a_non_compliant_device_is_worse_than_an_empty_port_and_an_error_beats_both():
    assert worst([EXIT_NO_DEVICE, EXIT_NON_COMPLIANT]) == EXIT_NON_COMPLIANT
    assert worst([EXIT_NON_COMPLIANT, EXIT_INCOMPLETE]) == EXIT_INCOMPLETE
    assert worst([EXIT_INCOMPLETE, EXIT_INTERNAL, EXIT_USAGE]) == EXIT_INTERNAL


def _document(verdict: str, complete: bool, serial: str | None = "SN0001") -> dict[str, Any]:
    return {
        "summary": {"verdict": verdict, "counts": {"PASS": 3, "FAIL": int(verdict != "COMPLIANT")}},
        "run": {"complete": complete, "stop_reason": None if complete else "run interrupted"},
        "dut": {"identification": "014CONFORM EMU001100SN0001\r\n", "serial": serial,
                "vendor": "CONFORM ", "model": "EMU001", "sdi12_version": "1.4"},
    }  # fmt: skip


def _result(code: int, document: dict[str, Any] | None, **more: Any) -> dict[str, Any]:
    return {"exit_code": code, "document": document, "errors": [], "folder": None,
            "files": None, "wall_s": 1.5} | more  # fmt: skip


def _junit_case(folder: Path, failed: bool) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    failure = '<failure message="R-4.4.12-05 FAIL">x</failure>' if failed else ""
    (folder / "junit.xml").write_text(
        '<?xml version="1.0"?><testsuites><testsuite name="pytest" tests="2">'
        '<testcase classname="t" name="test_identification"/>'
        f'<testcase classname="t" name="test_crc_value_and_encoding">{failure}</testcase>'
        "</testsuite></testsuites>",
        encoding="utf-8",
    )


def _rows(tmp_path: Path) -> list[dict[str, Any]]:
    _junit_case(tmp_path / "good", failed=False)
    _junit_case(tmp_path / "bad", failed=True)
    return [
        dut_row(Dut("good", "sim"), "sensor", _result(0, _document("COMPLIANT", True)),
                tmp_path / "good", tmp_path),
        dut_row(Dut("bad", "sim://?faults=wrong-crc"), "sensor",
                _result(1, _document("NON-COMPLIANT", True)), tmp_path / "bad", tmp_path),
        dut_row(Dut("gone", "/dev/ttyUSB9"), "sensor",
                _result(4, None, errors=["error: serial port /dev/ttyUSB9 does not exist"]),
                None, tmp_path),
    ]  # fmt: skip


def test_a_row_says_what_the_dut_was_and_a_dut_without_verdicts_is_not_complete(tmp_path):
    good, bad, gone = _rows(tmp_path)
    assert good["folder"] == "good" and good["complete"] and good["serial"] == "SN0001"
    assert good["identification"] == "014CONFORM EMU001100SN0001" and good["vendor"] == "CONFORM"
    assert bad["verdict"] == "NON-COMPLIANT" and bad["exit_code"] == 1
    assert gone["folder"] is None and gone["complete"] is False and gone["verdict"] is None
    assert gone["meaning"] == "usage error"


def test_rack_json_is_complete_only_when_every_dut_is_and_nothing_interrupted(tmp_path):
    rows = _rows(tmp_path)
    document = rack_document(rows, {"interrupted": False})
    assert document["rack"]["exit_code"] == EXIT_USAGE and not document["rack"]["complete"]
    finished = rack_document(rows[:2], {"interrupted": False})
    assert finished["rack"]["complete"] and finished["rack"]["exit_code"] == EXIT_NON_COMPLIANT
    stopped = rack_document(rows[:2], {"interrupted": True})
    assert not stopped["rack"]["complete"] and stopped["rack"]["exit_code"] == EXIT_INCOMPLETE


def test_junit_has_one_suite_per_dut_with_its_own_cases_and_a_verdict_case(tmp_path):
    write_junit(_rows(tmp_path), tmp_path)
    root = ET.parse(tmp_path / "junit.xml").getroot()
    suites = {s.get("name"): s for s in root.iter("testsuite")}
    assert list(suites) == ["good", "bad", "gone"]
    assert [c.get("name") for c in suites["good"].iter("testcase")] == [
        "test_identification", "test_crc_value_and_encoding", "verdict",
    ]  # fmt: skip
    assert (suites["good"].get("failures"), suites["good"].get("errors")) == ("0", "0")
    assert suites["bad"].get("failures") == "2"  # its CRC case and the rack's verdict case
    (case,) = suites["gone"].iter("testcase")  # no junit.xml of its own: an error, not green
    assert case.find("error") is not None and "does not exist" in case.find("error").text
    props = {p.get("name"): p.get("value") for p in suites["bad"].iter("property")}
    assert props["port"] == "sim://?faults=wrong-crc" and props["exit_code"] == "1"
    assert root.get("tests") == "7" and root.get("failures") == "2" and root.get("errors") == "1"


def test_index_html_has_a_row_per_dut_linking_its_report_and_escapes_what_devices_say(tmp_path):
    rows = _rows(tmp_path)
    (tmp_path / "good" / "report.html").write_text("<html></html>", encoding="utf-8")
    rows[1]["identification"] = "<script>alert(1)</script>"
    write_index(rack_document(rows, {"interrupted": False, "wall_s": 2.0}), tmp_path)
    page = (tmp_path / "index.html").read_text(encoding="utf-8")
    assert page.count('<tr class="code-') == 3
    assert '<a href="good/report.html">' in page and 'href="bad/report.html"' not in page
    assert "<script>" not in page and "&lt;script&gt;" in page
    assert "<link" not in page and "src=" not in page  # self-contained
    assert "exit 4 (usage error)" in page


def test_production_folders_are_named_by_serial_in_rack_order_a_repeated_serial_by_both(
    tmp_path,
):
    rows = []
    for name, serial in (("a", "SN 42/7"), ("b", "SN 42/7"), ("c", None), ("d", "SN9")):
        (tmp_path / name).mkdir()
        rows.append({"name": name, "serial": serial, "folder": name})
    rows.append({"name": "e", "serial": "SN9", "folder": None})  # wrote nothing
    name_by_serial(tmp_path, rows)
    assert [r["folder"] for r in rows] == ["SN_42_7", "SN_42_7-b", "c", "SN9", None]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["SN9", "SN_42_7", "SN_42_7-b", "c"]


def test_files_sent_back_by_a_worker_elsewhere_land_in_the_dut_folder(tmp_path):
    files = {"verdicts.json": b"{}", "sub/plan.json": b"[]"}
    folder = place_folder(tmp_path, Dut("far", "/dev/ttyUSB0", tx="ssh=h"),
                          _result(0, None, files=files))  # fmt: skip
    assert folder == tmp_path / "far"
    assert (folder / "sub" / "plan.json").read_bytes() == b"[]"


def test_a_verdict_says_when_its_run_was_not_complete():
    from conformance.rack.summary import verdict_text

    assert verdict_text({"verdict": "COMPLIANT", "complete": True}) == "COMPLIANT"
    assert verdict_text({"verdict": "NON-COMPLIANT", "complete": False}) == (
        "NON-COMPLIANT (incomplete)"
    )
    assert verdict_text({"verdict": "INCOMPLETE", "complete": False}) == "INCOMPLETE"
    assert verdict_text({"verdict": None, "complete": False}) == "no verdict"


def test_rack_json_holds_its_contract_and_the_contract_can_refuse(tmp_path):
    import json

    import jsonschema

    import conformance

    schema = json.loads((Path(conformance.__file__).parent / "schemas" / "rack-1.json")
                        .read_text(encoding="utf-8"))  # fmt: skip
    validator = jsonschema.Draft202012Validator(schema)
    facts = {"folder": str(tmp_path), "started": "2026-12-04T18:00:00+00:00",
             "finished": "2026-12-04T18:00:30+00:00", "wall_s": 30.0,
             "workers": ["popen"] * 3, "interrupted": False}  # fmt: skip
    document = rack_document(_rows(tmp_path), facts)
    validator.validate(document)
    renamed = json.loads(json.dumps(document))
    renamed["duts"][0]["exit"] = renamed["duts"][0].pop("exit_code")
    assert not validator.is_valid(renamed)
