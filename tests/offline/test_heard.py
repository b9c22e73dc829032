"""A transcript of a real-time link judged passively is host-stamped: one stalled stamp is
no evidence against the sensor (it may be the recording host's), while a deviation that
recurs at the same point of the same reply is the device's. A monitor's transcript of the
reference sensor FAILed R-7.0-12 on one stalled stamp (CI, issue 18).

On a bus of several sensors, a concurrent measurement is followed through its own data
commands, whatever the recorder said to the other sensors between (issue 23)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.protocol.commands import Kind
from conformance.replay.recording import read_recording, write_recording
from conformance.transcript import DUT, EventKind
from tests.support.shared_runs import copied_run

STALL = 7.5e-3  # s: beyond 1.66 ms + the ±5 ms the stamps declare


def _verdict(path: Path, out: Path, rid: str) -> dict:
    main(["judge", str(path), "--passive", "--role", "sensor", "--report-dir", str(out)])
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    return next(r for r in data["requirements"] if r["id"] == rid)


@pytest.fixture(scope="module")
def a_run(tmp_path_factory) -> Path:
    into = tmp_path_factory.mktemp("run") / "run"  # the session's clean run (shared_runs.py)
    run, code = copied_run(tmp_path_factory, into, "sim")
    assert code == 0  # the whole run: many aI!
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


def _heard_bus(tmp_path: Path, address: str | None = None, **kwargs):
    """The sensor rules' reading of a three-sensor bus recording (tests/support)."""
    from conformance.offline.heard import hear_sensors
    from conformance.replay.recording_link import load_recording, parse_recording, recording_port
    from tests.support.bus_of_sensors import record

    path = record(tmp_path / "bus", **kwargs)
    link = load_recording(parse_recording(recording_port(path, "jsonl")))
    return hear_sensors(link, address, None)


@pytest.mark.parametrize(
    ("code", "kind"),
    [
        ("C", Kind.CONCURRENT),
        ("CC", Kind.CONCURRENT),
        ("HA", Kind.HIGH_VOLUME_ASCII),
        ("HB", Kind.HIGH_VOLUME_BINARY),
    ],
)
def test_concurrent_measurements_on_a_bus_are_not_disturbed_by_the_other_sensors(
    tmp_path, code, kind
):
    """a<code>! to 0, 1 and 3, then the data of each: the traffic to the others between a
    sensor's start and its aD0!/aDB0! is what concurrent measurement is for (R-4.4.7-05,
    R-5.3-01), and the breaks in front of each do not abort it either (decision A4)."""
    heard = _heard_bus(tmp_path, code=code)
    concurrent = heard.of_kind(kind)
    assert [m.command.address for m in concurrent] == ["0", "1", "3"]
    assert [m.aborted_by for m in concurrent] == [None, None, None]
    whole = heard.of_kind(kind, whole=True)
    assert len(whole) == 3 and all(m.count for m in whole)
    assert all((m.binary_value_count if m.binary else m.value_count) == m.count for m in whole)
    assert not any("interrupted" in note for note in heard.assumptions), heard.assumptions


def test_a_command_to_the_same_sensor_still_sets_its_concurrent_measurement_aside(tmp_path):
    """0I! after 0C! and before 0D0! aborts sensor 0's measurement (R-4.4.7.1-01): its data
    rules are not judged on it, the others' are, and the note counts that one."""
    heard = _heard_bus(tmp_path, meddle={"0": "0I!"})
    assert [m.aborted_by for m in heard.of_kind(Kind.CONCURRENT)] == ["0I!", None, None]
    assert [m.command.address for m in heard.of_kind(Kind.CONCURRENT, whole=True)] == ["1", "3"]
    notes = [n for n in heard.assumptions if "interrupted" in n]
    assert len(notes) == 1 and notes[0].startswith("1 recorded measurement(s)"), notes


def test_an_m_measurement_is_still_disturbed_by_a_command_to_another_sensor():
    """After aM! and before its service request the recorder talks to no one else
    (R-4.4.5-06): 1I! there sets 0M!'s wait and data aside, as before."""
    from conformance.offline.heard import disturbance
    from conformance.view.rebuilt_records import rebuild_records
    from conformance.view.segments import read_view
    from tests.support.bus_of_sensors import as_heard, bus_of_sensors, measured_past_another

    bus, recorder = bus_of_sensors("01")
    measured_past_another(recorder)
    view = read_view(as_heard(bus))
    (rebuilt,) = rebuild_records(view).measurements
    assert disturbance(rebuilt, view) == "1I!"


def test_the_sensors_on_the_bus_are_known_by_their_first_address():
    """sensors_on: each answering address once, in address order, identified where an aI!
    reply was heard; a sensor moved by aAb! (and back) stays one sensor, not two."""
    from conformance.offline.heard import sensors_on
    from conformance.view.rebuilt_records import rebuild_records
    from conformance.view.segments import read_view
    from tests.support.bus_of_sensors import as_heard, bus_of_sensors, serial

    bus, recorder = bus_of_sensors("30")
    recorder.acknowledge("3")
    recorder.identify("0")
    assert recorder.change_address("5", "0").ok and recorder.identify("5").ok
    assert recorder.change_address("0", "5").ok
    found = sensors_on(rebuild_records(read_view(as_heard(bus))).exchanges)
    assert [s.address for s in found] == ["0", "3"]
    zero, three = found
    assert zero.identity is not None and zero.identity.optional == serial("0")
    assert zero.claim().version == "14" and zero.reply.startswith("014")
    assert three.identity is None and three.claim().reply is None  # no aI! heard: nulls
