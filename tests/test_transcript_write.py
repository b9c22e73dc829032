"""``Transcript.write_jsonl`` writes a block of lines at a time (an hour's capture is 43 MB
of lines, which formatted whole were the peak of a passive judgement's memory): the file is
byte for byte the lines :func:`json_line` gives one by one, across block boundaries, and it
still says whether every event had plain fields."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance import transcript
from conformance.transcript import DUT, TOOL, Event, EventKind, Transcript, json_line


def events(n: int, odd_at: int | None = None) -> list[Event]:
    out = [
        Event(EventKind.CHAR, DUT if i % 3 else TOOL, i * 0.0083, i * 0.0083 + 0.008, 0x30 + i % 9)
        for i in range(n)
    ]
    if odd_at is not None:  # an int time: written by json.dumps, not plain
        out[odd_at] = Event(EventKind.NOTE, TOOL, 1, 1, text="a note \u00b1")
    return out


@pytest.mark.parametrize("n", [0, 1, 6, 7, 12, 13])
@pytest.mark.parametrize("odd_at", [None, 0, 5])
def test_written_in_blocks_as_line_by_line(tmp_path: Path, monkeypatch, n: int, odd_at):
    monkeypatch.setattr(transcript, "WRITE_BLOCK", 6)
    odd = odd_at if odd_at is not None and odd_at < n else None
    evs = events(n, odd)
    path = tmp_path / "t.jsonl"
    plain = Transcript(evs).write_jsonl(str(path))
    assert path.read_text(encoding="utf-8") == "".join(json_line(e) for e in evs)
    assert plain is (odd is None)
