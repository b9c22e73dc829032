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


def test_line_parts_kept_per_fields_write_each_line_as_json_line(tmp_path: Path):
    """The parts kept per (kind, origin, wire, text, uncertainties) stand only for lines
    they are exact for: a negative zero, a non-finite time and a duration uncertainty
    each written as :func:`json_line` writes them, before and after a line that kept parts
    with fields equal to theirs."""
    inf, nan = float("inf"), float("nan")
    odd = [
        dict(uncertainty=-0.0),
        dict(duration_uncertainty=-0.0),
        dict(duration_uncertainty=0.0),
        dict(duration_uncertainty=2.5e-4),
        dict(uncertainty=inf),
        dict(uncertainty=nan),
        dict(duration_uncertainty=nan),
        dict(text="é\r\n"),
        dict(),
    ]
    evs: list[Event] = []
    t = 0.0
    for _ in range(3):  # each kind of line after one with the same fields
        for extra in odd:
            evs.append(Event(EventKind.CHAR, DUT, t, t + 0.008, 0x41, **extra))
            t += 0.008
    evs += [
        Event(EventKind.CHAR, TOOL, inf, inf, 0x41),
        Event(EventKind.CHAR, TOOL, 0.0, -0.0, 0x41),
        Event(EventKind.CHAR, TOOL, -0.0, 0.1, 0x41),
        Event(EventKind.BREAK, TOOL, 0.1, 0.2),
        Event(EventKind.CHAR, "collision", 0.2, 0.3, 0x41),
    ]
    path = tmp_path / "t.jsonl"
    assert Transcript(evs).write_jsonl(str(path)) is True
    assert path.read_text(encoding="utf-8") == "".join(json_line(e) for e in evs)
