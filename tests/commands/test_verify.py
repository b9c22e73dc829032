"""``sdi12-conform verify DIR`` (issue 24, item 4): a certifier checks a run folder without the
device. An untouched folder verifies; one edited verdict or one edited transcript line fails,
naming the file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.reports.manifest import digest


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("verify") / "run"
    assert main(["--port", "sim://?faults=response-too-late", "--report-dir", str(out)]) == 1
    return out


def copy(folder: Path, to: Path) -> Path:
    to.mkdir()
    for name in ("verdicts.json", "transcript.jsonl"):
        (to / name).write_bytes((folder / name).read_bytes())
    return to


def test_the_manifest_pins_the_recording(folder: Path):
    manifest = json.loads((folder / "verdicts.json").read_text())["manifest"]
    assert manifest["files"]["transcript.jsonl"] == digest(folder / "transcript.jsonl")
    assert len(manifest["catalog"]) == 64 and manifest["tool_version"]


def test_an_untouched_folder_verifies(folder: Path, tmp_path: Path, capsys):
    assert main(["verify", str(copy(folder, tmp_path / "a"))]) == 0
    out = capsys.readouterr().out
    assert "transcript.jsonl: sha256 matches" in out
    assert "all 115 verdicts follow from the recording" in out


def test_an_edited_verdict_fails_naming_the_file_and_the_rule(folder: Path, tmp_path: Path, capsys):
    run = copy(folder, tmp_path / "b")
    data = json.loads((run / "verdicts.json").read_text())
    row = next(r for r in data["requirements"] if r["id"] == "R-7.0-10")
    row["verdict"] = "PASS"  # a FAIL made to look like a PASS (counts left as they were)
    (run / "verdicts.json").write_text(json.dumps(data))
    assert main(["verify", str(run)]) == 1
    out = capsys.readouterr().out
    assert "verdicts.json: R-7.0-10 says PASS, the recording gives FAIL" in out
    assert "summary counts" in out


def test_an_edited_transcript_line_fails_naming_the_file(folder: Path, tmp_path: Path, capsys):
    run = copy(folder, tmp_path / "c")
    lines = (run / "transcript.jsonl").read_text().splitlines(keepends=True)
    lines[3] = lines[3].replace("0", "1", 1)
    (run / "transcript.jsonl").write_text("".join(lines))
    assert main(["verify", str(run)]) == 1
    assert "FAIL  transcript.jsonl: sha256 differs from the manifest" in capsys.readouterr().out


def test_a_folder_without_verdicts_is_a_usage_error(tmp_path: Path):
    assert main(["verify", str(tmp_path)]) == 4
    assert main(["verify", str(tmp_path / "none")]) == 4


def test_a_mistyped_folder_is_said_to_be_missing(tmp_path: Path, capsys):
    """First-hour look (2026-12-05): ``verify nonexist`` said "nonexist: not a run folder",
    as if the folder were there but wrong."""
    assert main(["verify", str(tmp_path / "none")]) == 4
    assert f"{tmp_path / 'none'}: no such folder" in capsys.readouterr().err
    (tmp_path / "file").write_text("", encoding="utf-8")
    assert main(["verify", str(tmp_path / "file")]) == 4
    assert "not a run folder" in capsys.readouterr().err
