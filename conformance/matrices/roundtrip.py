"""A run judged again through a logic-analyzer capture of itself (issue 11's round trip).

The run's transcript is exported as a sigrok session with the tool's TX on a second channel,
the capture is decoded at sample resolution and its cases are replayed against it, exactly as
a user's ``sdi12-conform export`` + ``sdi12-conform judge`` would. The verdicts must be the
live run's: a capture may decide what the live link left INCONCLUSIVE, never the reverse and
never another decided verdict. ``sdi12-conform matrix`` runs every fault this way; the test
suite's sensor matrix every fault of a measured timing rule and a third of the others
(:func:`in_capture_sample`; ``SDI12_MATRIX_CAPTURE=all`` for every one), to keep CI inside its
budget: the round trip is a second suite run per fault.
"""

from __future__ import annotations

import os
import tempfile
import zlib
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..conduct import conduct
from ..run import ConformanceRun
from ..transcript import Event, EventKind, plain_fields
from .sensor_matrix import (
    Item,
    MatrixRow,
    fault_port,
    fault_row,
    matrix_run,
    matrix_verdicts,
    row_from,
)

DECIDED = ("PASS", "FAIL", "WARN", "N/A")


class RoundTripError(RuntimeError):
    """The export or the judging could not give verdicts (the text says why)."""


def judged_through_capture(run_dir: Path, work: Path) -> dict:
    """Export the run in ``run_dir`` to ``work/run.sr`` (the tool's TX on a second channel),
    judge that capture as ``sdi12-conform judge capture.sr`` does (decoded, directions from
    the TX channel the export named in it, the run's cases replayed against it; no HTML)
    into ``work/capture/`` and return its verdicts (:meth:`ConformanceRun.verdict_lines`). A
    capture the judging would take passively raises, with the reason."""
    from ..replay.recording import RecordingError, read_recording

    try:
        events = read_recording(run_dir).events
    except RecordingError as exc:
        raise RoundTripError(f"{run_dir}: {exc}") from None
    return judged_events(events, str(run_dir), work)


def judged_events(events: list[Event], name: str, work: Path) -> dict:
    """:func:`judged_through_capture` of a run's events as its transcript.jsonl reads back
    (``name`` says which run in an error)."""
    from ..capture.held_sr import held_sr_captures
    from ..replay.recording import held_recordings

    work.mkdir(parents=True, exist_ok=True)
    with held_recordings(), held_sr_captures():
        return _judged_export(events, name, work)


def _judged_export(events: list[Event], name: str, work: Path) -> dict:
    """:func:`judged_events`, the decoded capture held in memory for its replay rather than
    written to ``capture/capture.jsonl`` (``plan(..., in_memory=True)``), while the caller's
    :func:`~conformance.replay.recording.held_recordings` lasts: deleted with the row
    anyway, its 10^4..10^5 lines were 3% of a row's CPU. The capture's samples likewise are
    held as the edges they read back as (:mod:`~conformance.capture.held_sr`), not written
    and read again: ~0.09 s of a ~1.1 s row; the decoder and the replay are the user's."""
    from ..capture.errors import CaptureError
    from ..capture.export import export_events
    from ..offline.judge import JudgeError, plan

    capture = work / "run.sr"
    again = work / "capture"
    try:
        note = EventKind.NOTE  # read off the enum once, not once an event (~2.5*10^4 a row)
        notes = [e for e in events if e.kind is note]
        export_events(events, str(capture), "sr", tool_channel=True, notes=notes, hold=True)
        # no --tx-channel: judge reads which channel is the tool's from the capture itself
        found = plan([str(capture), "--report-dir", str(again)], in_memory=True)
    except (CaptureError, JudgeError, ValueError) as exc:
        raise RoundTripError(f"{name}: {exc}") from None
    if found.replay is None:
        raise RoundTripError(f"{name}: its capture would be judged passively: {found.notes}")
    result = conduct(
        replace(found.replay, report_dir=str(again)), html=False, rootdir=again, files=()
    )
    document = result.run.verdict_lines() if result.run is not None else None
    if document is None:
        raise RoundTripError(f"{name}: its capture's replay gave no verdicts")
    return document


def live_run(
    report_dir: Path, port: str, role: str = "sensor", **options: Any
) -> tuple[dict, list[Event]]:
    """A matrix row's live run (:func:`~.sensor_matrix.matrix_run`: no report file): its
    verdict lines and its events as its transcript.jsonl would read back
    (:func:`recorded_events`)."""
    run, lines = matrix_run(report_dir, port, role, **options)
    return lines, recorded_events(run, report_dir)


def recorded_events(run: ConformanceRun, folder: Path) -> list[Event]:
    """The run's events as ``sdi12-conform export`` reads them from its transcript.jsonl: the
    transcript's own when every event has the plain fields a line reads back as exactly
    (what ``replay.recording.write_recording`` keeps as the file's reading), else written
    to ``folder/transcript.jsonl`` and read back."""
    from ..replay.recording import read_recording, write_recording

    events = run.link.transcript.events if run.link is not None else []
    if all(map(plain_fields, events)):
        return list(events)
    write_recording(folder / "transcript.jsonl", events)
    return read_recording(folder).events


def verdict_changes(live: dict, again: dict) -> tuple[str, ...]:
    """Where judging the capture changed the live run's verdicts: ``R-x: PASS -> FAIL``, plus
    one entry if the capture was not replayed. A capture deciding a requirement the live run
    left INCONCLUSIVE is no change (the capture's timing can be better than the link's)."""
    kind = str(again["run"]["link"].get("kind", ""))
    changes = [] if kind.startswith("replay") else [f"capture judged by {kind!r}, not replayed"]
    before = {r["id"]: r["verdict"] for r in live["requirements"]}
    after = {r["id"]: r["verdict"] for r in again["requirements"]}
    for rid in sorted(before.keys() | after.keys()):
        a, b = before.get(rid, "absent"), after.get(rid, "absent")
        if a != b and not (a == "INCONCLUSIVE" and b in DECIDED):
            changes.append(f"{rid}: {a} -> {b}")
    return tuple(changes)


def capture_changes(run_dir: Path, live: dict, work: Path) -> tuple[str, ...]:
    """:func:`verdict_changes` of the run in ``run_dir`` judged through its capture; an
    export or judging that fails is itself a change (never an exception in a matrix)."""
    try:
        return verdict_changes(live, judged_through_capture(run_dir, work))
    except RoundTripError as exc:
        return (str(exc),)


def event_changes(events: list[Event], name: str, live: dict, work: Path) -> tuple[str, ...]:
    """:func:`capture_changes` of a run's events (:func:`live_run`)."""
    try:
        return verdict_changes(live, judged_events(events, name, work))
    except RoundTripError as exc:
        return (str(exc),)


#: one fault in this many goes through its capture in the test suite's sensor matrix...
CAPTURE_SAMPLE = 3
#: ...and every fault of a rule judged on a measured figure
MEASURED_TIMING = frozenset(("R-4.1-01", "R-7.0-01", "R-7.0-09", "R-7.0-10", "R-7.0-12"))


def in_capture_sample(fault: str) -> bool:
    """Whether the test suite's matrix judges ``fault`` through its capture too: a fixed
    third of the faults, chosen by a hash of the name (the same in every worker process and
    every run; ``SDI12_MATRIX_CAPTURE=all`` takes every fault)."""
    return os.environ.get("SDI12_MATRIX_CAPTURE") == "all" or in_default_sample(fault)


def in_default_sample(fault: str) -> bool:
    """Whether ``fault`` is in the fixed sample :func:`in_capture_sample` takes when not told
    to take every fault (the test suite spreads the sampled rows over its modules by it)."""
    from ..emulator import FAULTS

    spec = FAULTS.get(fault)
    if spec is not None and MEASURED_TIMING.intersection(spec.violates):
        return True  # decoded at sample resolution, a measured figure is what could move
    return zlib.crc32(fault.encode()) % CAPTURE_SAMPLE == 0


def row_through_sampled_capture(item: Item) -> MatrixRow:
    """:func:`row_through_capture` for the faults :func:`in_capture_sample` takes, the
    live row alone for the others."""
    if in_capture_sample(item[0]):
        return row_through_capture(item)
    return fault_row(item, matrix_verdicts(fault_port(item), **dict(item[3])))


def row_through_capture(item: Item) -> MatrixRow:
    """A sensor fault's matrix row (the ``row`` of
    :func:`conformance.matrices.sensor_matrix.fault_matrix`) with its run also judged through a
    capture of itself."""
    with tempfile.TemporaryDirectory(prefix="sdi12-capture-") as tmp:
        live_dir = Path(tmp) / "live"
        data, events = live_run(live_dir, fault_port(item), **dict(item[3]))
        changes = event_changes(events, str(live_dir), data, Path(tmp))
        return replace(fault_row(item, data), capture=changes)


def recorder_row_through_capture(fault: str) -> MatrixRow:
    """A recorder fault's matrix row with its run also judged through a capture of itself."""
    from ..recorder.faults import RECORDER_FAULTS

    spec = RECORDER_FAULTS[fault]
    with tempfile.TemporaryDirectory(prefix="sdi12-capture-") as tmp:
        live_dir = Path(tmp) / "live"
        data, events = live_run(live_dir, f"sim://?recorder-faults={fault}", role="recorder")
        row = row_from(fault, spec.violates, data, spec.inconclusive)
        return replace(row, capture=event_changes(events, str(live_dir), data, Path(tmp)))
