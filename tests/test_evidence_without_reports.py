"""A run that writes no report file (a matrix row's runs, ``files=()``) attaches each case's
evidence by its label alone: the events behind it are read by the report files only (issue
22, live28). The labels, findings and verdicts are those of the run that keeps the events,
and a case handing something that is no record fails as it did."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance.case import Case, events_of
from conformance.conduct import conduct
from conformance.results import CaseRecord
from conformance.run import RunOptions
from conformance.tool_recorder.records import Attempt, Exchange
from conformance.transcript import EventKind, wire_event


def _record() -> CaseRecord:
    return CaseRecord("t::c", "c", ("R-4.4-01",))


def _exchange() -> Exchange:
    ch = wire_event(EventKind.CHAR, "sensor", 0.02, 0.0283, 0x30)
    cmd = wire_event(EventKind.CHAR, "tool", 0.0, 0.0083, 0x30)
    return Exchange(None, "0!", [Attempt(None, [cmd], [ch], "ok", 0.03)])


def test_evidence_keeps_its_events_by_default():
    case = Case(_record())
    ex = _exchange()
    case.evidence("reply", ex)
    assert case.record.evidence == [("reply", events_of(ex))]
    assert len(case.record.evidence[0][1]) == 2


def test_evidence_without_events_keeps_the_label():
    case = Case(_record(), evidence_events=False)
    ex = _exchange()
    case.evidence("reply", ex)
    case.evidence("both", [ex, [ex], None])
    case.evidence("events", ex.attempts[0].reply_events)
    assert case.record.evidence == [("reply", []), ("both", []), ("events", [])]


@pytest.mark.parametrize("events", [True, False])
@pytest.mark.parametrize("bad", [3, "text", [_exchange(), object()]])
def test_evidence_of_no_record_is_the_same_error_either_way(events, bad):
    case = Case(_record(), evidence_events=events)
    with pytest.raises(TypeError, match="no events in"):
        case.evidence("bad", bad)


def _run(folder: Path, port: str, role: str, files: tuple[str, ...] | None):
    folder.mkdir()
    options = RunOptions(port=port, role=role, report_dir=str(folder))
    result = conduct(options, html=False, rootdir=folder, files=files)
    assert result.run is not None
    return result.run


@pytest.mark.parametrize(
    ("port", "role"),
    [("sim://?faults=wrong-crc", "sensor"), ("sim://?recorder-faults=short-break", "recorder")],
)
def test_a_run_without_report_files_judges_as_one_with_them(tmp_path, port, role):
    kept = _run(tmp_path / "kept", port, role, None)
    bare = _run(tmp_path / "bare", port, role, ())
    assert list((tmp_path / "bare").iterdir()) == []
    assert bare.verdict_lines() == kept.verdict_lines()
    labels = [[label for label, _ in c.evidence] for c in kept.cases]
    assert [[label for label, _ in c.evidence] for c in bare.cases] == labels
    assert any(events for c in kept.cases for _, events in c.evidence)
    assert not any(events for c in bare.cases for _, events in c.evidence)
    details = [[(f.requirement, f.verdict, f.detail) for f in c.findings] for c in kept.cases]
    assert [[(f.requirement, f.verdict, f.detail) for f in c.findings] for c in bare.cases] == (
        details
    )
