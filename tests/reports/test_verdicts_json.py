"""verdicts.json is a contract (``sdi12-conform/verdicts/1``): CI jobs and other tools parse it.

A clean and a faulty run are validated against the JSON Schema shipped in the package, and
against what a schema cannot say: every catalog requirement of the role is listed once, the
counts and the overall verdict follow from the requirement verdicts, and the tests and findings
refer to each other. The schema itself is shown to reject broken documents, so a validation
that passes means something.
"""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections import Counter
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from conformance.catalog import for_role
from conformance.reports.verdicts_json import SCHEMA as SCHEMA_ID

RUNS = {"clean": ("sim", 0), "faulty": ("sim://?faults=no-service-request", 1)}
VERDICTS = ("PASS", "FAIL", "WARN", "INCONCLUSIVE", "N/A", "ERROR")


def load_schema() -> dict[str, Any]:
    """The schema as an installed package carries it (package data, not a repo path)."""
    text = (resources.files("conformance") / "schemas" / "verdicts-1.json").read_text("utf-8")
    return json.loads(text)


VALIDATOR = jsonschema.Draft202012Validator(load_schema())


@pytest.fixture(
    scope="module",
    params=[pytest.param(k, marks=pytest.mark.slow) if k == "faulty" else k for k in sorted(RUNS)],
)
def run(request: pytest.FixtureRequest, tmp_path_factory) -> tuple[str, Path, dict[str, Any]]:
    port, expected_exit = RUNS[request.param]
    out = tmp_path_factory.mktemp(request.param)
    proc = subprocess.run(
        [sys.executable, "-m", "conformance.cli", "--port", port, "--report-dir", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == expected_exit, proc.stdout + proc.stderr
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    return request.param, out, data


def errors(document: dict[str, Any]) -> list[str]:
    return [f"{list(e.absolute_path)}: {e.message}" for e in VALIDATOR.iter_errors(document)]


def test_schema_is_valid_json_schema_with_the_contract_id():
    schema = load_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    assert schema["properties"]["schema"]["const"] == SCHEMA_ID == "sdi12-conform/verdicts/1"


def test_run_writes_all_four_files(run):
    _, out, data = run
    for name in ("report.html", "verdicts.json", "junit.xml", "transcript.jsonl"):
        assert (out / name).stat().st_size > 0, name
    suite = ET.parse(out / "junit.xml").getroot()
    assert len(suite.findall(".//testcase")) == len(data["tests"])
    with (out / "transcript.jsonl").open(encoding="utf-8") as fh:
        first = json.loads(fh.readline())
    assert {"kind", "origin", "start", "end", "wire"} <= set(first)


def test_document_validates_against_the_schema(run):
    _, _, data = run
    assert errors(data) == []


def test_requirements_are_the_roles_catalog(run):
    _, _, data = run
    role = data["run"]["role"]
    catalog = {r.id: r for r in for_role(role)}
    listed = [r["id"] for r in data["requirements"]]
    assert len(listed) == len(set(listed)), "a requirement is listed twice"
    assert set(listed) == set(catalog)
    for r in data["requirements"]:
        assert r["level"] == catalog[r["id"]].level
        assert r["testable"] == catalog[r["id"]].testable(role)
        if not r["testable"]:
            assert r["verdict"] == "N/A" and r["findings"][0]["detail"].startswith("untestable")


def test_summary_follows_from_the_requirements(run):
    _, _, data = run
    tally = Counter(r["verdict"] for r in data["requirements"])
    assert data["summary"]["counts"] == {v: tally.get(v, 0) for v in VERDICTS}
    expected = "NON-COMPLIANT" if tally["FAIL"] else "COMPLIANT"
    assert data["summary"]["verdict"] == expected
    assert data["run"]["complete"] is True


def test_requirement_verdict_is_its_worst_finding(run):
    _, _, data = run
    rank = {"N/A": 0, "PASS": 1, "WARN": 2, "INCONCLUSIVE": 3, "FAIL": 4, "ERROR": 5}
    for r in data["requirements"]:
        assert r["verdict"] == max((f["verdict"] for f in r["findings"]), key=rank.get), r["id"]


def test_tests_and_findings_refer_to_each_other(run):
    _, _, data = run
    test_ids = {t["id"] for t in data["tests"]}
    known = {r["id"] for r in data["requirements"]}
    for t in data["tests"]:
        assert set(t["requirements"]) <= known, t["id"]
    for r in data["requirements"]:
        for f in r["findings"]:
            assert f["test"] in test_ids or (
                f["test"] == "" and r["verdict"] in ("N/A", "INCONCLUSIVE")
            )


def test_faulty_run_fails_what_the_fault_breaks(run):
    name, _, data = run
    failed = {r["id"] for r in data["requirements"] if r["verdict"] == "FAIL"}
    assert failed == ({"R-4.4.6-02"} if name == "faulty" else set())
    failing_tests = {t["id"] for t in data["tests"] if t["verdict"] == "FAIL"}
    assert bool(failing_tests) == (name == "faulty")


@pytest.mark.parametrize(
    ("break_it", "why"),
    [
        (lambda d: d.pop("tests"), "a contract key is missing"),
        (lambda d: d.__setitem__("schema", "sdi12-conform/verdicts/2"), "another version"),
        (lambda d: d["summary"].__setitem__("verdict", "PASSED"), "unknown overall verdict"),
        (lambda d: d["summary"]["counts"].pop("N/A"), "a count is missing"),
        (lambda d: d["summary"]["counts"].__setitem__("SKIPPED", 1), "an unknown count"),
        (lambda d: d["requirements"][0].__setitem__("verdict", "OK"), "unknown verdict"),
        (lambda d: d["requirements"][0].__setitem__("findings", []), "verdict without finding"),
        (lambda d: d["requirements"][0]["findings"][0].pop("measured_ms"), "a finding key"),
        (lambda d: d["requirements"][0].__setitem__("id", "4.4.6-02"), "an ID off the catalog"),
        (lambda d: d["run"].__setitem__("role", "logger"), "unknown role"),
        (lambda d: d["run"]["link"].__setitem__("can_break", "yes"), "a boolean as text"),
        (lambda d: d["dut"].__setitem__("sdi12_version", "14"), "version not dotted"),
        (lambda d: d["tests"][0].__setitem__("duration_s", -1), "negative duration"),
        (lambda d: d.__setitem__("duts", [{"address": "0"}]), "a bus sensor without its fields"),
        (lambda d: d.__setitem__("duts", {"0": None}), "the bus sensors not a list"),
    ],
)
def test_schema_rejects_a_broken_document(run, break_it, why):
    _, _, data = run
    broken = copy.deepcopy(data)
    break_it(broken)
    assert errors(broken), f"the schema accepted a document where {why}"


def test_a_live_run_leaves_the_bus_sensors_out(run):
    """``duts`` (every sensor on the bus) is a passive run's: a live run drives one DUT, the
    ``dut`` block's, and its document stays valid without it (Session.bus_sensors)."""
    _, _, data = run
    assert "duts" not in data and errors(data) == []
