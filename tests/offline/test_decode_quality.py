"""Decode quality per sensor (issue 23, item 3): on a capture of two sensors, one of them
3 % fast, each sensor's report gives its own characters' bit-rate error and errors, so the
fast one is seen as such beside an exact one."""

from __future__ import annotations

import json

import pytest

from conformance.capture import export_events
from conformance.cli import main
from conformance.protocol.timing import BIT_TIME
from conformance.transcript import DUT
from tests.capture.test_export import brk, chars


def _exchange(address: str, start: float, fast_pct: float = 0.0) -> tuple[list, float]:
    """A break, ``aI!`` and the sensor's reply 9.5 ms after it, the reply at a bit rate
    ``fast_pct`` % above 1200 baud; the events and where they end."""
    command = chars(f"{address}I!", start + 0.02)
    bit = BIT_TIME / (1 + fast_pct / 100)
    reply = chars(
        f"{address}14CONFORM EMU001100SN000{address}\r\n", command[-1].end + 9.5e-3, DUT, bit
    )
    return [brk(start, 0.013), *command, *reply], reply[-1].end


def test_each_sensor_of_a_capture_gets_its_own_decode_figures(tmp_path):
    first, end = _exchange("0", 0.05)
    second, _ = _exchange("1", end + 0.1, fast_pct=3.0)
    capture = tmp_path / "two.sr"
    export_events([*first, *second], capture, sample_rate=1e6)
    out = tmp_path / "judged"
    assert main(["judge", str(capture), "--role", "sensor", "--report-dir", str(out)]) == 1
    notes = {
        a: " ".join(
            json.loads((out / f"sensor-{a}" / "verdicts.json").read_text())["dut"]["assumptions"]
        )
        for a in "01"
    }
    for a in "01":
        assert f"decode quality of sensor '{a}'" in notes[a], notes[a]
    failed = {
        a: {
            r["id"]
            for r in json.loads((out / f"sensor-{a}" / "verdicts.json").read_text())["requirements"]
            if r["verdict"] == "FAIL"
        }
        for a in "01"
    }
    assert failed == {"0": set(), "1": {"R-4.1-01"}}  # 3 % fast is outside the bit rate's tolerance
    median = {a: float(notes[a].split("(median ")[1].split(" %")[0]) for a in "01"}
    assert median["0"] == pytest.approx(0.0, abs=0.3)
    assert median["1"] == pytest.approx(3.0, abs=0.3)
    assert "28 character(s)" in notes["1"] and "0 with a parity error" in notes["1"]


def test_a_sensor_s_framing_errors_are_counted_on_widened_or_merged_events():
    """A decode that widened its stamps (the glitch filter beside an edge) or merged a TX
    channel holds new event objects; its problems still name the characters they are of."""
    from dataclasses import replace
    from types import SimpleNamespace

    from conformance.capture.uart import Decoded
    from conformance.offline.decode_quality import decode_quality
    from conformance.transcript import BUS, Event, EventKind

    first = [Event(EventKind.CHAR, BUS, t, t + 0.00833, wire=0x30) for t in (1.0, 1.01, 1.02)]
    problems = [Decoded("char", first[1], first[1].start, first[1].end, True)]  # framing error
    events = [replace(e, uncertainty=5.2e-5) for e in first]  # widened: other objects
    decoded = SimpleNamespace(baud_error_pct=[0.0, 0.5, -0.5], problems=problems, baud=1200)
    said = decode_quality(decoded, events, events[1:], "sensor '0'")
    assert said is not None and "2 character(s)" in said and "1 with a framing error" in said
    assert "bit rate -0.50..+0.50 % off 1200 baud (median +0.00 %)" in said, said


def _by_identity(decoded, events):
    """The lookup CharRates replaces: a map from every character to its error."""
    from conformance.transcript import EventKind

    in_order = [e for e in events if e.kind is EventKind.CHAR]
    rates = decoded.baud_error_pct
    return dict(zip(map(id, in_order), rates, strict=True)) if len(rates) == len(in_order) else {}


@pytest.mark.parametrize("seed", range(40))
def test_the_rate_of_a_character_is_the_one_a_map_by_identity_gives(seed):
    """Characters with tied starts, breaks among them, characters out of time order,
    characters not of the decode, an error list of another length: each character's
    error is what a map from every character to its error gave."""
    import random
    from array import array
    from types import SimpleNamespace

    from conformance.offline.decode_quality import CharRates
    from conformance.transcript import BUS, Event, EventKind

    rnd = random.Random(seed)
    events = []
    t = 0.0
    for _ in range(rnd.randint(0, 30)):
        t += rnd.choice([0.0, 0.0, 0.001, 0.00833])  # ties of start are common
        kind = EventKind.BREAK if rnd.random() < 0.15 else EventKind.CHAR
        events.append(Event(kind, BUS, t, t + 0.00833, wire=rnd.randint(0, 127)))
    if events and rnd.random() < 0.3:  # out of time order
        i = rnd.randrange(len(events))
        events.append(events.pop(i))
    n = sum(e.kind is EventKind.CHAR for e in events) + (rnd.random() < 0.15)
    errors = array("f", [rnd.choice([0.5, -1.25, float("nan"), 3.0]) for _ in range(n)])
    decoded = SimpleNamespace(baud_error_pct=errors)
    strangers = [Event(EventKind.CHAR, BUS, e.start, e.end, wire=e.wire) for e in events[:3]]
    looked_up = CharRates(decoded, events)
    mapped = _by_identity(decoded, events)
    for c in [*events, *strangers]:
        got, want = looked_up.get(c), mapped.get(id(c))
        assert (got is None and want is None) or got == want or (got != got and want != want)
