"""A capture with the recorder's TX channel: the TX decoded first into ``Marks`` (no event
made of it) and each bus event made once with its origin (issue 22, the capture half of a
fault-matrix row) gives what the two channels decoded apart and matched after, event by
event, gave: the same events, origins, counters, notes and errors, in the same order."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.capture import decode as decode_module
from conformance.capture.decode import RECORDER_ORIGIN, SENSOR_ORIGIN, decode_capture
from conformance.capture.errors import CaptureError
from conformance.capture.export import export_events
from conformance.capture.levels import edge_array
from conformance.capture.writers import Channel, write_sr
from conformance.transcript import Event, EventKind, full_event
from tests.support.capture_digest import decode_digest, traffic


def matched_after(bus: list[Event], tx: list[Event], tolerance: float) -> list[Event]:
    """The rule as it was written before the TX became marks: every bus event made the
    sensors', then one pass over both lists remaking those the TX shows."""
    out = [replace(e, origin=SENSOR_ORIGIN) for e in bus]
    j = 0
    for i, ev in enumerate(out):
        while j < len(tx) and tx[j].start < ev.start - tolerance:
            j += 1
        if j < len(tx):
            t = tx[j]
            if (
                abs(t.start - ev.start) <= tolerance
                and t.kind is ev.kind
                and (ev.kind is not EventKind.CHAR or t.wire == ev.wire)
            ):
                out[i] = replace(ev, origin=RECORDER_ORIGIN)
                j += 1
    return out


def apart(path: str, **kw):
    """The bus and the TX channel decoded each on its own, matched after."""
    bus = decode_capture(path, keep=False, **kw)
    tx = decode_capture(path, channel="TOOL_TX", keep=False, **kw)
    tolerance = 0.5 / 1200 + 2 * bus.uncertainty_s
    return bus, tx, matched_after(bus.events, tx.events, tolerance)


def fields(e: Event) -> tuple:
    return (e.kind, e.origin, repr(e.start), repr(e.end), e.wire, e.text, e.uncertainty)


@pytest.mark.parametrize("seed", [1, 4, 9])
@pytest.mark.parametrize("glitch_us", [None, 150.0])
def test_bus_marked_as_made_is_the_two_decodes_matched_after(seed, glitch_us, tmp_path):
    path = str(tmp_path / "run.sr")
    export_events(traffic(seed, seconds=4.0), path, "sr", tool_channel=True)
    kw = {} if glitch_us is None else {"glitch_filter": glitch_us * 1e-6}
    bus, tx, want = apart(path, **kw)
    got = decode_capture(path, tx_channel="TOOL_TX", keep=False, **kw)
    assert [fields(e) for e in got.events] == [fields(e) for e in want]
    origins = {e.origin for e in got.events}
    assert origins == {SENSOR_ORIGIN, RECORDER_ORIGIN}
    unseen = len(tx.events) - sum(e.origin == RECORDER_ORIGIN for e in want)
    note = [f"{unseen} events on the TX channel were not seen on the bus"] if unseen else []
    assert got.notes == [*bus.notes, f"TX channel 'TOOL_TX': {tx.polarity} polarity", *note]
    counts = ("chars", "framing_errors", "parity_errors", "glitches", "breaks", "pulses")
    assert [getattr(got, c) for c in counts] == [getattr(bus, c) for c in counts]
    assert decode_digest(replace(got, events=bus.events, notes=bus.notes, tx_channel=None)) == (
        decode_digest(bus)
    )


def test_a_widened_bus_is_matched_again_at_its_own_tolerance(tmp_path, monkeypatch):
    """Where the glitch filter widens the bus's stamps after the decode matched them, the
    match is made again at the wider tolerance: here a TX channel a little late, so that
    only the wider tolerance takes its characters for the bus's."""
    events = [e for e in traffic(3, seconds=2.0) if e.kind is not EventKind.NOTE]
    late = [
        replace(e, start=e.start + 0.0006, end=e.end + 0.0006) for e in events if e.origin == "tool"
    ]
    rate, tx_path = 100_000.0, str(tmp_path / "tx.sr")
    channels = [
        Channel("SDI12", 1, edge_array(events, rate, 0.0)),
        Channel("TOOL_TX", 1, edge_array(late, rate, 0.0)),
    ]
    write_sr(tx_path, channels, rate, round((events[-1].end + 0.02) * rate))
    widened = {"n": 0}
    real = decode_module._filtered

    def filtered(out, glitch, width):
        real(out, glitch, width)
        if out.channel == "SDI12":  # as if a pulse beside an edge had been taken out
            widened["n"] += 1
            out.uncertainty_s += 0.0005
            out.events = [replace(e, uncertainty=e.uncertainty + 0.0005) for e in out.events]

    monkeypatch.setattr(decode_module, "_filtered", filtered)
    got = decode_capture(tx_path, tx_channel="TOOL_TX", keep=False)
    bus = decode_capture(tx_path, keep=False)
    tx = decode_capture(tx_path, channel="TOOL_TX", keep=False)
    assert widened["n"] == 2
    want = matched_after(bus.events, tx.events, 0.5 / 1200 + 2 * bus.uncertainty_s)
    assert [fields(e) for e in got.events] == [fields(e) for e in want]
    narrow = matched_after(bus.events, tx.events, 0.5 / 1200 + 2 * (bus.uncertainty_s - 0.0005))
    assert [e.origin for e in narrow] != [e.origin for e in want]  # the wider one decided


def test_errors_come_in_the_order_they_did(tmp_path):
    """The bus's error first, then a TX channel that is the bus's, then the TX's own."""
    path = str(tmp_path / "run.sr")
    export_events(traffic(2, seconds=1.0), path, "sr", tool_channel=True)
    with pytest.raises(CaptureError, match="no channel 'NOPE'"):
        decode_capture(path, channel="NOPE", tx_channel="ALSO_NOT", keep=False)
    with pytest.raises(CaptureError, match="is the bus channel itself"):
        decode_capture(path, channel="SDI12", tx_channel="SDI12", keep=False)
    with pytest.raises(CaptureError, match="no channel 'ALSO_NOT'"):
        decode_capture(path, tx_channel="ALSO_NOT", keep=False)


def test_a_tx_channel_that_never_changes_is_refused_as_before(tmp_path):
    """A TX channel with no traffic: the TX's own refusal, after the bus decoded."""
    path = str(tmp_path / "run.sr")
    quiet = [full_event(EventKind.CHAR, "dut", 0.05, 0.0583, 0x30, "", 0.0, None)]
    export_events([*quiet, *traffic(2, seconds=1.0)[:0]], path, "sr", tool_channel=True)
    with pytest.raises(CaptureError, match="never changes level"):
        decode_capture(path, tx_channel="TOOL_TX", keep=False)
