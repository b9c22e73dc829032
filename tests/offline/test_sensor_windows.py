"""The passive sensor run read a window at a time (issue 22, ``offline.sensor_windows``):
every session a sensor run judges (its exchanges and measurements with each one's
disturbance, its replies' timing and framing findings, the notes, the sensors on the bus,
the identity and rule set) must be what the whole-run path made, kept as the oracle in
``tests/support/whole_run_heard.py`` (``offline/heard.py`` of base-s61, which cut the whole
view, the whole run's segments and records): on busy-bus captures, the shared real captures,
three-sensor bus recordings with sensor faults and meddling recorders (every direction
inferred), and whole sim runs with sensor faults (the directions given, and taken away)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from conformance.conduct import run_into
from conformance.judges import wire
from conformance.links.errors import PortError
from conformance.matrices.sensor_matrix import fault_port
from conformance.offline import heard
from conformance.replay.recording import read_recording, write_recording
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.tool_recorder.records import Exchange, Measurement
from conformance.transcript import BUS, Transcript
from tests.offline.test_judge_memory import busy_capture
from tests.support import whole_run_heard as oracle
from tests.support.bus_of_sensors import record

SHARED = Path("/work/shared/captures")


def _load(path: Path, kind: str):
    return load_recording(parse_recording(recording_port(str(path), kind)))


def _listed(link):
    """The oracle's recording as base-s61 held it: its events one list of objects (a compact
    store, ``conformance.event_store``, makes them again at each read, and the whole-run
    path found a character's decode figures by identity in a second read of the list)."""
    link.transcript = Transcript(list(link.transcript.events))
    return link


def _exchange(x: Exchange) -> tuple:
    attempts = [
        (a.reason, a.start, a.end, a.sequence, a.retry, a.reply_text, len(a.reply_events))
        for a in x.attempts
    ]
    return (x.text, x.reply_text, x.answered, x.ok, attempts)


def _measurement(m: Measurement) -> tuple:
    return (
        _exchange(m.start), m.ttt, m.count, m.aborted_by, m.reply_end, m.service_request_end,
        [_exchange(d) for d in m.data], [len(m.waited_events)],
    )  # fmt: skip


def _session(s) -> tuple:
    """What the sensor cases and the reports read of a session, as plain values."""
    return (
        [_exchange(x) for x in s.exchanges],
        [_measurement(m) for m in s.measurements],
        s.assumptions, [(b.address, b.identity, b.reply) for b in s.on_bus], s.bus_sensors(),
        s.identity, s.version, s.address,
        s.address_notes, s.claim(),
    )  # fmt: skip


def _whole_timing(s) -> list:
    """The whole-run judges over the oracle session's segments, as the cases judged them."""
    segs, stamps = s.segments, s.stamp_uncertainty
    return [
        *wire.judge_response_start(segs, stamps),
        *wire.judge_gaps(segs, stamps),
        wire.judge_reply_bit_rate(segs, stamps),
        *wire.judge_framing(segs, stamps),
    ]


def _timing(s) -> list:
    r = s.records
    return [*r.response_start, *r.gaps, r.bit_rate, *r.framing]


def _compare(path: Path, kind: str, extra: tuple[str | None, ...] = ()) -> int:
    """Every address on the bus, all of them together (None), ``extra`` and an address
    nobody answered at, judged both ways on loads of their own (nothing shared); both
    loads must fail alike where one does. The addresses compared."""
    try:
        old_link, new_link = _listed(_load(path, kind)), _load(path, kind)
    except PortError as exc:
        with pytest.raises(PortError, match=str(exc)[:40]):
            _load(path, kind)
        return 0
    addresses = [s.address for s in oracle.bus_sensors(old_link)]
    assert [s.address for s in heard.bus_sensors(new_link)] == addresses
    asked = [None, *addresses, *extra, "x"]
    for address in asked:
        for version in (None, "1.3"):
            old = oracle.hear_sensors(old_link, address, version)
            new = heard.hear_sensors(new_link, address, version)
            assert _session(new) == _session(old), (path, address, version)
            assert _timing(new) == _whole_timing(old), (path, address, version)
    recorder_old = oracle.hear_recorder(old_link, None)
    recorder_new = heard.hear_recorder(new_link, None)
    assert recorder_new.assumptions == recorder_old.assumptions
    assert recorder_new.bus_sensors() == recorder_old.bus_sensors()
    assert "_view" not in new_link.transcript.__dict__  # no whole-run view was cut
    return len(asked)


def test_busy_bus_captures_are_read_as_the_whole_run(tmp_path: Path):
    for minutes in (0.05, 0.5):
        path = tmp_path / f"busy{minutes}.sr"
        busy_capture(path, minutes)
        assert _compare(path, "sr") == 12


@pytest.mark.skipif(not SHARED.is_dir(), reason="the shared captures are not here")
def test_the_shared_captures_are_read_as_the_whole_run():
    for path in sorted(SHARED.glob("*.sr")):
        _compare(path, "sr")


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"code": "CC"},
        {"code": "HA"},
        {"code": "HB"},
        {"code": "M"},
        {"meddle": {"0": "0I!"}},
        {"meddle": {"1": "3I!"}},
        {"faults": {"0": ["crc-missing"], "3": ["response-too-late"]}},
        {"faults": {"1": ["no-service-request"]}, "code": "M"},
        {"faults": {"0": ["values-over-35"], "1": ["wrong-crc"]}, "code": "CC"},
    ],
    ids=str,
)
def test_bus_recordings_are_read_as_the_whole_run(tmp_path: Path, kwargs: dict):
    from conformance.emulator import FAULTS

    for names in (kwargs.get("faults") or {}).values():
        assert all(n in FAULTS for n in names), names
    path = record(tmp_path / "bus", **kwargs)
    assert _compare(path, "jsonl") == 5


SIM_FAULTS = (
    "no-service-request",
    "chatter-before-service-request",
    "break-aborts-concurrent",
    "multiline-no-etx",
    "replies-after-retry",
    "inter-char-gap",
)


@pytest.mark.parametrize("fault", [None, *SIM_FAULTS])
def test_sim_runs_with_sensor_faults_are_read_as_the_whole_run(tmp_path: Path, fault):
    """A whole sensor run (directions given: origins tool and dut), and the same with every
    origin ``bus`` (the directions inferred, the windows cut with those sides)."""
    from conformance.emulator import FAULTS

    if fault is not None and fault not in FAULTS:
        pytest.fail(f"no fault {fault!r}")
    port = "sim" if fault is None else fault_port((fault, (), "14", ()))
    run_into(tmp_path / "run", port, "sensor")
    given = tmp_path / "run" / "transcript.jsonl"
    assert _compare(given, "jsonl", extra=("1", "")) >= 4
    events = read_recording(given).events
    heard_only = tmp_path / "bus.jsonl"
    write_recording(heard_only, [replace(e, origin=BUS) for e in events])
    assert _compare(heard_only, "jsonl") >= 3
