"""The writer table (``conformance.reports.writers``): a run's folder holds exactly the files
the table and pytest's renderings name, in the table's order, and a format added to the table
is written with no other change (issue 21, item 8: a new report format is one row)."""

from __future__ import annotations

import json

from conformance.conduct import conduct
from conformance.reports import writers
from conformance.reports.manifest import digest
from conformance.run import RunOptions

QUICK = {"keyword": "identification"}


def test_a_run_folder_holds_the_tables_files_and_the_renderings(tmp_path):
    result = conduct(RunOptions(port="sim", report_dir=str(tmp_path), **QUICK), rootdir=tmp_path)
    assert result.document is not None
    written = {p.name for p in tmp_path.iterdir() if not p.name.startswith(".")}
    expected = {w.file for w in writers.REPORT_WRITERS} | set(writers.PYTEST_RENDERINGS)
    assert written == expected
    # the transcript comes first: verdicts.json's manifest pins it as written
    pinned = result.document["manifest"]["files"]["transcript.jsonl"]
    assert pinned == digest(tmp_path / "transcript.jsonl")


def test_a_format_added_to_the_table_is_written(tmp_path, monkeypatch):
    def summary_line(run, directory):
        path = directory / "summary.txt"
        path.write_text(f"{run.verdict} {len(run.results or [])}\n", encoding="utf-8")
        return path

    row = writers.ReportWriter("summary.txt", "the verdict in one line", summary_line)
    monkeypatch.setattr(writers, "REPORT_WRITERS", (*writers.REPORT_WRITERS, row))
    options = RunOptions(port="sim", report_dir=str(tmp_path), **QUICK)
    result = conduct(options, html=False, rootdir=tmp_path)
    verdict = json.loads((tmp_path / "verdicts.json").read_text())["summary"]["verdict"]
    assert (tmp_path / "summary.txt").read_text().split()[0] == verdict
    assert result.document["summary"]["verdict"] == verdict
