"""A capture loaded for judging keeps of its decode's problems only the characters' (issue
22: every break of a busy bus was also kept as a problem item, 14,875 objects and 1.9 MB at
an hour, held to the end of the judgement, though only the decode-quality notes read the
problems, and only those of characters). The decode handed to another caller keeps all of
them, and what the notes read is the same either way."""

from __future__ import annotations

import pytest

import conformance.capture.decode as capture_decode
from conformance.capture import decode_capture, export_events
from conformance.capture.uart import character_problems
from conformance.offline.decode_quality import decode_quality, problems_by_character
from conformance.protocol.timing import BIT_TIME
from conformance.replay.recording_link import load_recording, parse_recording
from conformance.transcript import DUT, EventKind
from tests.capture.test_export import brk, chars


@pytest.fixture
def capture(tmp_path, monkeypatch):
    """A break, a spacing pulse, a glitch and a character with a glitch inside: problems of
    every kind, two of them a character's."""
    monkeypatch.setattr(capture_decode, "_LAST", None)
    events = [
        brk(0.05, 0.013),
        *chars("0D0!", 0.07),
        *chars("0+1.5\r\n", 0.115, DUT),
        brk(0.2, 8e-3),  # a spacing pulse
        brk(0.25, 60e-6),  # a glitch on the idle line
        *chars("0", 0.26),
        brk(0.26 + 5.2 * BIT_TIME, 80e-6),  # a glitch inside that character
    ]
    path = tmp_path / "problems.sr"
    export_events(events, path, sample_rate=1e6)
    return path


def test_a_loaded_capture_keeps_its_characters_problems_alone(capture):
    whole = decode_capture(capture)  # kept for the loading, which takes it over
    kinds = {p.kind for p in whole.problems}
    assert {"break", "pulse", "glitch", "char"} <= kinds, kinds
    link = load_recording(parse_recording(f"recording:{capture}?format=sr"))
    assert link.decoded is not None
    assert link.decoded.problems == character_problems(whole.problems)
    assert link.decoded.problems and {p.kind for p in link.decoded.problems} == {"char"}
    assert {p.kind for p in whole.problems} == kinds  # the caller's decode keeps every one


def test_the_notes_read_the_same_of_the_kept_problems(capture):
    whole = decode_capture(capture)
    link = load_recording(parse_recording(f"recording:{capture}?format=sr"))
    assert link.decoded is not None
    assert problems_by_character(link.decoded) == problems_by_character(whole)
    events = link.transcript.events
    read = [e for e in events if e.kind is EventKind.CHAR]
    note = decode_quality(link.decoded, events, read, "sensor '0'")
    assert note is not None and "1 with a glitch inside" in note
    assert note == decode_quality(whole, events, read, "sensor '0'")
