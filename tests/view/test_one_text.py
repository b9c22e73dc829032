"""A transmission's text held once per text (``view.segments.one_text``, issue 22, branch
memory25), not by :func:`sys.intern`: the same object for equal texts while kept, every
text kept until the table is full, and then let go, the texts still equal."""

from __future__ import annotations

import pytest

from conformance.view import segments
from conformance.view.segments import one_text


def test_equal_texts_are_one_object(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(segments, "_TEXTS", {})
    first = "".join(["0", "D0!"])
    again = "".join(["0D", "0!"])
    assert first is not again
    assert one_text(first) is first and one_text(again) is first


def test_the_table_is_bounded_and_its_texts_stay_equal(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(segments, "_TEXTS", {})
    monkeypatch.setattr(segments, "TEXTS_MAX", 8)
    texts = [f"{i}M!" for i in range(20)]
    assert [one_text(t) for t in texts] == texts
    assert len(segments._TEXTS) <= 8
    assert one_text(texts[-1]) is texts[-1]


def test_a_window_s_transmissions_share_their_texts():
    from conformance.transcript import TOOL, Event, EventKind
    from conformance.view.windows import window_view

    def command(at: float) -> list[Event]:
        out = [Event(EventKind.BREAK, TOOL, at, at + 0.013, 0)]
        for k, c in enumerate("0D0!"):
            t = at + 0.03 + k * 0.00833
            out.append(Event(EventKind.CHAR, TOOL, t, t + 0.00833, ord(c)))
        return out

    view = window_view(command(0.0) + command(1.0), None)
    a, b = view.transmissions[0].text, view.transmissions[1].text
    assert a == b == "0D0!" and a is b
