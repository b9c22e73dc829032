"""A matrix row's runs write no report file (``roundtrip.live_run``, the capture's replay
run): the row reads its verdicts from memory (``ConformanceRun.verdict_lines``). Here the
fast path against the slow one: the lines are exactly what verdicts.json holds of the same
run, the events a row's run gives are what a whole run's transcript.jsonl reads back as (and
a transcript a line would not read back exactly is written and read), and a sensor row
through its capture comes out the same either way. The recorder's row through its capture,
from memory, is ``short-break``'s row of tests/matrices/test_recorder_matrix.py (in the
default selection): exact there means its capture changed nothing (``MatrixRow.exact``
counts ``capture``) and every declared requirement flagged, what a test here asserted of
the same row made a second time."""

from __future__ import annotations

import shutil
import tempfile
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

from conformance.capture.export import export_events
from conformance.capture.transcript_io import read_transcript_jsonl
from conformance.conduct import conduct, run_into, run_once
from conformance.emulator import FAULTS
from conformance.matrices import combinations, roundtrip, sensor_matrix
from conformance.matrices.sensor_matrix import fault_row
from conformance.offline.judge import plan
from conformance.protocol.version import V14
from conformance.replay.recording import read_recording
from conformance.run import RunOptions
from conformance.transcript import TOOL, Event, EventKind


def projection(document: dict) -> dict:
    """What ``verdict_lines`` says it holds, taken from a written verdicts.json."""
    return {
        "run": {
            "link": document["run"]["link"],
            "stop_reason": document["run"]["stop_reason"],
        },
        "summary": {"verdict": document["summary"]["verdict"]},
        "requirements": [
            {
                "id": r["id"],
                "verdict": r["verdict"],
                "findings": [
                    {"verdict": f["verdict"], "detail": f["detail"]} for f in r["findings"]
                ],
            }
            for r in document["requirements"]
        ],
    }


@pytest.mark.parametrize(
    ("port", "role"),
    [
        ("sim", "sensor"),
        ("sim://?faults=response-too-late", "sensor"),
        ("sim://?recorder-faults=short-break", "recorder"),
    ],
)
def test_verdict_lines_are_what_verdicts_json_holds_of_the_same_run(tmp_path, port, role):
    options = RunOptions(port=port, role=role, report_dir=str(tmp_path))
    result = conduct(options, html=False, rootdir=tmp_path)
    assert result.document is not None and result.run is not None
    lines = result.run.verdict_lines()
    assert lines == projection(result.document)
    assert any(r["verdict"] in ("FAIL", "WARN") for r in lines["requirements"]) is (port != "sim")


def test_a_row_run_writes_no_file_and_gives_the_events_its_transcript_reads_back(tmp_path):
    folder = tmp_path / "live"  # the same folder both times: the options note names it
    data = run_into(folder, "sim://?faults=wrong-crc")
    written = read_transcript_jsonl(str(folder / "transcript.jsonl"))  # parsed, not kept
    shutil.rmtree(folder)
    lines, events = roundtrip.live_run(folder, "sim://?faults=wrong-crc")
    assert list(folder.iterdir()) == []
    assert events == written
    assert [type(e.start) for e in events] == [type(e.start) for e in written]
    assert lines == projection(data)


def test_events_a_line_would_not_read_back_exactly_are_written_and_read(tmp_path):
    odd = Event(EventKind.CHAR, TOOL, 1, 1.0083, wire=0x30)  # an int time reads back a float
    run = SimpleNamespace(link=SimpleNamespace(transcript=SimpleNamespace(events=[odd])))
    events = roundtrip.recorded_events(run, tmp_path)
    assert (tmp_path / "transcript.jsonl").is_file()
    assert events == read_transcript_jsonl(str(tmp_path / "transcript.jsonl"))
    assert type(events[0].start) is float


def whole_row(fault: str) -> roundtrip.MatrixRow:
    """The row as it was made before: every report file written, verdicts.json read."""
    item = (
        fault,
        tuple(FAULTS[fault].violates),
        getattr(FAULTS[fault], "version", None) or V14,
        (),
    )
    with tempfile.TemporaryDirectory() as tmp:
        live = Path(tmp) / "live"
        data = run_into(live, roundtrip.fault_port(item))
        work = Path(tmp) / "capture"
        work.mkdir()
        events = read_recording(live).events
        notes = [e for e in events if e.kind is EventKind.NOTE]
        export_events(events, str(work / "run.sr"), "sr", tool_channel=True, notes=notes)
        found = plan([str(work / "run.sr"), "--report-dir", str(work / "again")])
        assert found.replay is not None
        again = conduct(
            replace(found.replay, report_dir=str(work / "again")), html=False, rootdir=work
        ).document
        assert again is not None
        return replace(fault_row(item, data), capture=roundtrip.verdict_changes(data, again))


@pytest.mark.slow
@pytest.mark.parametrize("fault", ["response-too-late", "crc-missing"])
def test_a_row_through_its_capture_is_the_same_made_either_way(fault):
    item = (
        fault,
        tuple(FAULTS[fault].violates),
        getattr(FAULTS[fault], "version", None) or V14,
        (),
    )
    fast = roundtrip.row_through_capture(item)
    assert fast == whole_row(fault)
    assert fast.exact


@pytest.mark.slow
def test_a_plain_row_and_a_combination_are_the_same_from_verdicts_json():
    fault = "wrong-crc"
    item = (fault, tuple(FAULTS[fault].violates), V14, ())
    assert sensor_matrix._row(item) == fault_row(item, run_once(sensor_matrix.fault_port(item)))
    faults = combinations.CI_COMBINATIONS[0]
    made = combinations.combo_row(faults)
    whole = combinations.check(
        faults, combinations.declared_for(faults), run_once(combinations.combo_port(faults))
    )
    assert replace(made, cpu_s=0.0) == whole
