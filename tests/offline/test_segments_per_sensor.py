"""A passive judgement of a bus judges each sensor's reply timing and framing over its own
transmissions' segments a window at a time (``offline.sensor_windows``), and holds no
whole-run list of segments (issue 22: that list, split by sensor for every run, held 11.5
MB at an hour of a busy capture from the first sensor's run to the end). Each sensor's
findings are the whole-run judges' over the whole run's segments of its address, and are
let go with its records."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance.cli import main
from conformance.judges import wire
from conformance.offline import heard
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.transcript import Transcript
from conformance.view.runs import transcript_segments


def _load(capture: Path):
    return load_recording(parse_recording(recording_port(str(capture), "sr")))


def _timing(session: heard.HeardSensors) -> list:
    r = session.records
    assert r is not None
    return [*r.response_start, *r.gaps, r.bit_rate, *r.framing]


@pytest.mark.parametrize("address", ["0", "3", "9", "x", "", "12", None])
def test_a_sensors_timing_is_judged_on_its_share_of_the_whole_runs(capture: Path, address):
    """Equal to the whole-run judges' findings over the whole run's segments whose text
    starts with the address, in order (an address no sensor answered at: none; a string
    that is no address: as a split of the whole run by first character answered it; None:
    every segment)."""
    link = _load(capture)
    session = heard.hear_sensors(link, address, None)
    whole = transcript_segments(Transcript(link.transcript.events))
    segs = [s for s in whole if address is None or s.text[:1] == address]
    stamps = session.stamp_uncertainty
    expected = [
        *wire.judge_response_start(segs, stamps),
        *wire.judge_gaps(segs, stamps),
        wire.judge_reply_bit_rate(segs, stamps),
        *wire.judge_framing(segs, stamps),
    ]
    assert _timing(session) == expected
    assert bool(segs) == (address is None or address in set("0123456789"))
    assert "_segments" not in link.transcript.__dict__  # the whole list never made
    assert "_view" not in link.transcript.__dict__  # nor the whole view


def test_released_with_the_records(capture: Path):
    link = _load(capture)
    before = {a: _timing(heard.hear_sensors(link, a, None)) for a in "0369"}
    heard.release_records(link, keep={"6"})
    assert set(link.__dict__["_sensor_records"][1]) == {"6"}
    for a, found in before.items():  # kept or made again, the same
        assert _timing(heard.hear_sensors(link, a, None)) == found


def test_a_judgement_holds_no_whole_run_segments(
    capture: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    """``judge`` of a bus (its reports searched for every finding's exchange and every
    whole-run case's worst value): after each run, the loaded recording holds no whole-run
    list of segments, and only the records of the sensors still to be judged."""
    from conformance.commands import passive
    from conformance.offline.fixtures import _LOADED

    held: list[tuple[str, bool, list[str]]] = []
    run_role = passive._run_role

    def looking(job, port, args, console):
        result = run_role(job, port, args, console)
        link = _LOADED[port]
        records = link.__dict__["_sensor_records"][1]
        held.append((job.label, "_segments" in link.transcript.__dict__, sorted(records)))
        return result

    monkeypatch.setattr(passive, "_run_role", looking)
    code = main(["judge", str(capture), "--report-dir", str(tmp_path / "reports")])
    assert code == 2  # incomplete: no aI!, no measurement seen
    # a sensor's records are let go once the next run starts (passive.release)
    assert held[-1] == ("recorder", False, [])
    assert all(not whole for _, whole, _ in held), held
    assert [shares for _, _, shares in held[:10]] == [[a] for a in "0123456789"], held
