"""Issue 22, matrix round 12: a stimulus's mark (``LiveCut.mark``, one per stimulus) is a
named tuple: its fields and defaults as the frozen dataclass had them, read by name, never
changed, made without a ``object.__setattr__`` call per field."""

from __future__ import annotations

import pytest

from conformance.ports import open_sim, parse_sim
from conformance.sensor.session import SensorSession
from conformance.view.live_cut import Mark, live_cut


def test_a_mark_keeps_its_fields_and_defaults_and_cannot_change() -> None:
    mark = Mark(12)
    assert (mark.first, mark.cut, mark.transmissions, mark.chars) == (12, False, 0, 0)
    assert mark.current is None and mark.pending is None and mark.last_heard is None
    with pytest.raises(AttributeError):
        mark.first = 3  # type: ignore[misc]
    assert isinstance(mark, tuple)  # no dataclass __init__: a tuple made in one call


def test_a_live_mark_is_the_cut_s_state_at_the_stimulus() -> None:
    opened = open_sim(parse_sim("sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.exchange("I")
    events = opened.link.transcript.events
    cut = live_cut(opened.link.transcript)
    mark = cut.mark(events)
    assert mark.first == len(events) and mark.cut
    assert mark.transmissions == len(cut.cut.transmissions)
    assert mark.current is cut.cut._current and mark.last_heard is cut.cut._last_heard
    session.fresh_exchange("I")
    began = cut.since(opened.link.transcript.events, mark)
    assert began is not None and [t.text for t in began] == ["0I!"]
