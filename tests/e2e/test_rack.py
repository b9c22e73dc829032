"""A rack of simulated DUTs (issue 23, item 4), as a user runs it: each DUT's run in a
worker process of its own, its four reports in its own folder, the rack's summary, the worst
exit status; every way of naming a rack wrongly is one line and exit 4.

The rack of RFC 2217 emulators and its Ctrl-C are in test_rack_realtime.py."""

from __future__ import annotations

import io
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import jsonschema
import pytest

import conformance
from conformance.cli import main
from conformance.interrupts import GUARD
from conformance.rack.worker import run_dut
from conformance.run import RunOptions
from tests.support.socket_worker import socket_worker_host

REPORTS = {"verdicts.json", "report.html", "junit.xml", "transcript.jsonl"}


SCHEMA = json.loads(
    (Path(conformance.__file__).parent / "schemas" / "rack-1.json").read_text(encoding="utf-8")
)


def _rack_json(folder: Path) -> dict:
    """rack.json, checked against its contract (schemas/rack-1.json)."""
    data = json.loads((folder / "rack.json").read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator(SCHEMA).validate(data)
    return data


def test_a_sim_rack_with_a_faulty_dut_exits_1_with_a_folder_per_dut_named_by_serial(tmp_path):
    rack = tmp_path / "rack"
    code = main(["--port", "sim", "--port", "sim://?faults=wrong-crc",
                 "--profile", "production", "--report-dir", str(rack)])  # fmt: skip
    assert code == 1
    data = _rack_json(rack)
    assert data["rack"]["exit_code"] == 1 and data["rack"]["complete"]
    good, bad = data["duts"]
    assert (good["name"], good["exit_code"], good["verdict"]) == ("1-sim", 0, "COMPLIANT")
    assert (bad["name"], bad["exit_code"], bad["verdict"]) == ("2-sim", 1, "NON-COMPLIANT")
    # --profile production names each folder by the serial; the second unit of that serial
    # (every emulator says SN0001) by its serial and its name
    assert (good["folder"], bad["folder"]) == ("SN0001", "SN0001-2-sim")
    assert good["serial"] == bad["serial"] == "SN0001" and good["complete"] and bad["complete"]
    for row in (good, bad):
        assert {p.name for p in (rack / row["folder"]).iterdir()} >= REPORTS
        assert not (rack / row["folder"] / ".sdi12-conform.lock").exists()
    verdicts = json.loads((rack / "SN0001-2-sim" / "verdicts.json").read_text(encoding="utf-8"))
    failed = {r["id"] for r in verdicts["requirements"] if r["verdict"] == "FAIL"}
    assert failed == {"R-4.4.12-05"}  # the fault's own rule, as a single run finds it
    assert (good["failed"], bad["failed"]) == ([], ["R-4.4.12-05"])  # the row says which
    suites = ET.parse(rack / "junit.xml").getroot().findall("testsuite")
    assert [s.get("name") for s in suites] == ["1-sim", "2-sim"]
    assert [s.get("failures") for s in suites] == ["0", "2"]
    page = (rack / "index.html").read_text(encoding="utf-8")
    assert 'href="SN0001/report.html"' in page and 'href="SN0001-2-sim/report.html"' in page
    assert '<span class="rid">R-4.4.12-05</span>' in page
    assert not (rack / ".sdi12-conform.lock").exists()


@pytest.mark.slow  # 10 s: the recorder role's cases
def test_a_rack_file_gives_names_roles_and_a_port_that_cannot_open_its_own_exit(tmp_path, capsys):
    (tmp_path / "bench.toml").write_text(
        '[[dut]]\nname = "bay1"\nport = "sim"\n'
        '[[dut]]\nname = "bay2"\nport = "/dev/ttyNOSUCH"\n'
        '[[dut]]\nname = "logger"\nport = "sim"\nrole = "recorder"\n',
        encoding="utf-8",
    )
    rack = tmp_path / "out"
    code = main(["rack", str(tmp_path / "bench.toml"), "-k", "identification or test_4_4_1",
                 "--report-dir", str(rack)])  # fmt: skip
    assert code == 4  # usage error beats compliant: bay2's port does not exist
    rows = {r["name"]: r for r in _rack_json(rack)["duts"]}
    assert rows["bay1"]["exit_code"] == 0 and rows["bay1"]["folder"] == "bay1"
    assert rows["logger"]["role"] == "recorder" and rows["logger"]["folder"] == "logger"
    assert rows["bay2"]["exit_code"] == 4 and rows["bay2"]["folder"] is None
    assert "does not exist" in rows["bay2"]["errors"][-1]
    out = capsys.readouterr().out
    assert "bay2 (/dev/ttyNOSUCH): no verdict, exit 4 (usage error)" in out
    assert "rack: exit 4 (usage error, the worst DUT's)" in out


def test_a_worker_that_cannot_start_is_an_internal_error_row(tmp_path):
    rack = tmp_path / "rack"
    code = main(["--port", "sim", "--port", "sim", "-k", "test_identification",
                 "--tx", "popen", "--tx", "popen//python=/nonexistent/python",
                 "--report-dir", str(rack)])  # fmt: skip
    assert code == 3
    first, second = _rack_json(rack)["duts"]
    assert first["exit_code"] == 0 and first["worker"] == "popen"
    assert second["exit_code"] == 3 and not second["complete"] and second["folder"] is None
    assert "did not start" in second["errors"][0]


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["rack"], "name the rack file first"),
        (["rack", "{tmp}/none.toml"], "none.toml: No such file"),
        (["--rack", "{tmp}/bad.toml"], "unknown key(s) speed"),
        (["--rack", "{tmp}/bad.toml", "--port", "sim"], "give no --port"),
        (["--port", "sim", "--port", "sim", "--baseline", "{tmp}"], "--baseline compares one"),
        (["--port", "sim", "--port", "sim", "--tx", "nothing"], "names no worker"),
        (["--port", "sim", "--port", "sim", "--req", "R-9.9-99"], "R-9.9-99"),
        (["--port", "sim", "--port", "sim", "--declaration", "{tmp}/x.toml"], "DUT 1-sim:"),
        (["--port", "sim", "--port", "sim", "--address", "all"], "one DUT per port"),
    ],
)
def test_a_rack_named_wrongly_is_one_line_and_exit_4(tmp_path, capsys, argv, says):
    (tmp_path / "bad.toml").write_text("[[dut]]\nport = 'sim'\nspeed = 9600\n", encoding="utf-8")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main([*argv, "--report-dir", str(tmp_path / "rack")]) == 4
    err = capsys.readouterr().err.strip()
    assert says in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "rack" / "rack.json").exists()


def test_a_worker_on_another_host_sends_its_folder_back(tmp_path):
    """The worker's side of a rack on another host (``report_dir`` None): its run goes into
    a folder of its own and the files come back in the result (here in this process)."""
    options = RunOptions(port="sim://?faults=wrong-crc", keyword="test_crc_value_and_encoding")
    job = {"options": vars(options), "plan": "never", "report_dir": None,
           "declaration_text": None, "name": "far"}  # fmt: skip
    try:
        result = run_dut(job)
    finally:
        GUARD.reset()
    assert result["exit_code"] == 1 and result["folder"] is None
    assert REPORTS - {"report.html", "junit.xml"} <= set(result["files"])
    assert result["document"]["summary"]["verdict"] == "NON-COMPLIANT"
    assert result["document"]["run"]["complete"] is True


def test_rack_help_shows_the_rack_file_and_main_help_the_rack_options(capsys):
    assert main(["rack", "--help"]) == 0
    out = capsys.readouterr().out
    assert "[[dut]]" in out and "sdi12-conform --rack FILE" in out
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "--rack FILE" in out and "--tx SPEC" in out and "rack" in out


def test_a_worker_elsewhere_gets_its_declaration_and_sends_its_reports_back(tmp_path):
    """A worker that is not a local process (execnet's socket server on loopback stands for
    another host): its declaration goes over as text, its folder's files come back."""
    (tmp_path / "decl.toml").write_text('address = "0"\n', encoding="utf-8")
    rack = tmp_path / "rack"
    with socket_worker_host() as spec:
        (tmp_path / "bench.toml").write_text(
            '[[dut]]\nname = "near"\nport = "sim"\n'
            '[[dut]]\nname = "far"\nport = "sim://?faults=wrong-crc"\n'
            f'declaration = "decl.toml"\ntx = "{spec}"\n',
            encoding="utf-8",
        )
        code = main(["rack", str(tmp_path / "bench.toml"), "--profile", "production",
                     "--report-dir", str(rack)])  # fmt: skip
    assert code == 1
    near, far = _rack_json(rack)["duts"]
    assert far["worker"] == spec and far["exit_code"] == 1 and far["folder"] == "SN0001-far"
    assert {p.name for p in (rack / far["folder"]).iterdir()} >= REPORTS
    verdicts = json.loads((rack / far["folder"] / "verdicts.json").read_text(encoding="utf-8"))
    copy = Path(verdicts["dut"]["declaration"])  # the worker's own copy, by the file's name
    assert copy.name == "decl.toml" and copy.parent != tmp_path
    assert verdicts["run"]["complete"] and near["exit_code"] == 0


def test_ctrl_c_before_the_rack_starts_touches_no_dut(tmp_path, capsys):
    from rich.console import Console

    from conformance.rack.run import run_rack
    from conformance.rack.spec import duts_from_ports

    duts = duts_from_ports(["sim", "sim"])
    GUARD.requested = True  # as the guard records a Ctrl-C while the rack is checked
    try:
        code = run_rack(duts, [RunOptions(port=d.port) for d in duts], tmp_path, "never",
                        Console(file=io.StringIO()))  # fmt: skip
    finally:
        GUARD.reset()
    assert code == 2
    assert "nothing was sent to any DUT" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_worker_whose_python_lacks_the_tool_says_so(tmp_path):
    """A host whose Python has no sdi12-conform (here: the same Python without its site
    packages, in a folder without the source) is a row that says what to install where."""
    python = tmp_path / "python"
    python.write_text(f'#!/bin/sh\nexec {sys.executable} -S -E "$@"\n', encoding="utf-8")
    python.chmod(0o755)
    rack = tmp_path / "rack"
    code = main(["--port", "sim", "--port", "sim", "-k", "test_identification",
                 "--tx", "popen", "--tx", f"popen//python={python}//chdir={tmp_path}",
                 "--report-dir", str(rack)])  # fmt: skip
    assert code == 3
    first, second = _rack_json(rack)["duts"]
    assert first["exit_code"] == 0
    assert second["exit_code"] == 3 and second["folder"] is None
    assert "cannot run sdi12-conform" in second["errors"][0]
    assert "No module named 'conformance'" in second["errors"][0]
