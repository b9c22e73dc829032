"""A decode kept compact for judging holds of its problems the characters' alone while it
decodes (issue 22, branch memory21): a busy bus's every break was a problem item (with its
event and stamps, ~300 bytes) until the loader dropped all but the characters', the decode's
one transient that grew with the capture: an hour's 14,875, two hours' 29,751, 4.5 MB more,
whose pages stayed resident after the load (the loaded state's RSS 57.0 -> 62.1 MB between 60
and 120 minutes, now 52.5 -> 53.4). The counts are the same, the notes read the same
problems, and a caller that may read every problem never gets such a decode."""

from __future__ import annotations

import pytest

import conformance.capture.decode as capture_decode
from conformance.capture import decode_capture, export_events
from conformance.capture.uart import character_problems
from conformance.replay.recording_link import load_recording, parse_recording
from tests.offline.test_loaded_problems import capture  # noqa: F401 (a fixture)
from tests.view.test_view_memory import busy_events  # the capture benchmark's busy bus

COUNTS = ("chars", "breaks", "pulses", "glitches", "framing_errors", "parity_errors")


@pytest.fixture(autouse=True)
def _nothing_kept(monkeypatch):
    monkeypatch.setattr(capture_decode, "_LAST", None)


def _counts(d: capture_decode.CaptureDecode) -> tuple[int, ...]:
    return tuple(getattr(d, name) for name in COUNTS) + (d.partial_frames,)


@pytest.mark.parametrize("bulk", [True, False])
def test_a_compact_decode_keeps_the_characters_problems_alone(capture, monkeypatch, bulk):  # noqa: F811
    monkeypatch.setattr(capture_decode, "BULK", bulk)
    whole = decode_capture(capture, keep=False)
    compact = decode_capture(capture, keep=False, compact=True)
    assert {"break", "pulse", "glitch", "char"} <= {p.kind for p in whole.problems}
    assert compact.characters_problems_only and not whole.characters_problems_only
    assert compact.problems == character_problems(whole.problems)
    assert {p.kind for p in compact.problems} == {"char"}
    assert _counts(compact) == _counts(whole)


def test_a_busy_bus_decoded_compact_holds_no_break_item(tmp_path):
    events = busy_events(40.0)
    path = tmp_path / "busy.sr"
    export_events(events, path, sample_rate=1e6)
    d = decode_capture(path, keep=False, compact=True)
    assert d.breaks > 100 and d.breaks == sum(e.kind.value == "break" for e in events)
    assert d.problems == []  # the clean bus's breaks counted and stored, none held as an item


def test_a_kept_compact_decode_serves_compact_callers_alone(capture):  # noqa: F811
    compact = decode_capture(capture, compact=True)  # kept: judge's plan() decodes so
    again = decode_capture(capture)  # a caller that may read every problem: decoded again
    assert again is not compact and {"break", "pulse", "glitch"} <= {p.kind for p in again.problems}
    assert _counts(again) == _counts(compact)
    link = load_recording(parse_recording(f"recording:{capture}?format=sr"))
    assert link.decoded is not None
    assert link.decoded.problems == character_problems(again.problems)


def test_the_loader_takes_the_kept_compact_decode_over(capture, monkeypatch):  # noqa: F811
    decoded = []
    real = capture_decode._decode_capture

    def counted(*args, **kwargs):
        decoded.append(args[0])
        return real(*args, **kwargs)

    monkeypatch.setattr(capture_decode, "_decode_capture", counted)
    kept = decode_capture(capture, compact=True)
    link = load_recording(parse_recording(f"recording:{capture}?format=sr"))
    assert len(decoded) == 1 and capture_decode._LAST is None  # taken over, not decoded again
    assert link.decoded is not None and link.decoded.problems == kept.problems
