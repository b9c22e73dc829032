"""A transcript of a real-time link judged passively is host-stamped: one stalled stamp is
no evidence against the sensor (it may be the recording host's), while a deviation that
recurs at the same point of the same reply is the device's. A monitor's transcript of the
reference sensor FAILed R-7.0-12 on one stalled stamp (CI, issue 18)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.replay.recording import read_recording, write_recording
from conformance.transcript import DUT, EventKind

STALL = 7.5e-3  # s: beyond 1.66 ms + the ±5 ms the stamps declare


def _verdict(path: Path, out: Path, rid: str) -> dict:
    main(["judge", str(path), "--passive", "--role", "sensor", "--report-dir", str(out)])
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    return next(r for r in data["requirements"] if r["id"] == rid)


@pytest.fixture(scope="module")
def a_run(tmp_path_factory) -> Path:
    run = tmp_path_factory.mktemp("run")
    assert main(["--port", "sim", "--report-dir", str(run)]) == 0  # the whole run: many aI!
    return run


def _host_stamped(run: Path, out: Path, stalled_replies: int) -> Path:
    """The run's transcript as a live link would have stamped it (±5 ms, no run options, so
    it is judged as what it is), with the 3rd character of the first ``stalled_replies``
    ``aI!`` replies stamped :data:`STALL` late (and the rest of that reply after it)."""
    events = [e for e in read_recording(run).events if e.kind is not EventKind.NOTE]
    events = [replace(e, uncertainty=5e-3) for e in events]
    starts = [k for k, e in enumerate(events) if e.origin == DUT and e.char7 == ord("0")
              and k + 2 < len(events) and events[k + 1].char7 == ord("1")
              and events[k + 2].char7 == ord("4")]  # fmt: skip
    assert len(starts) >= min(stalled_replies, 6)  # a place seen often enough to tell
    for k in starts[:stalled_replies]:
        j = k + 2
        while j < len(events) and events[j].origin == DUT:
            events[j] = replace(events[j], start=events[j].start + STALL, end=events[j].end + STALL)
            if events[j].char7 == 0x0A:
                break
            j += 1
    path = out / "transcript.jsonl"
    write_recording(path, events)
    return path


def test_one_stalled_stamp_is_no_fail(a_run, tmp_path):
    path = _host_stamped(a_run, tmp_path, stalled_replies=1)
    r = _verdict(path, tmp_path / "judged", "R-7.0-12")
    assert r["verdict"] == "INCONCLUSIVE", r


def test_a_gap_that_recurs_in_every_reply_fails(a_run, tmp_path):
    path = _host_stamped(a_run, tmp_path, stalled_replies=99)
    r = _verdict(path, tmp_path / "judged", "R-7.0-12")
    assert r["verdict"] == "FAIL", r
