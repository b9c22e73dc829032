"""A live run's transcript is cut once, as it grows (issue 22, fault-matrix round 10:
:mod:`conformance.view.live_cut`): each stimulus's records read the transmissions of that
one cut, and the whole-run view is that cut's, only where they are what ``read_view`` of
the same events gives; everywhere else the events are cut on their own, as before."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance.matrices.roundtrip import live_run
from conformance.sensor import session as session_module
from conformance.transcript import DUT, TOOL, Event, EventKind, Transcript, to_wire_7e1
from conformance.view import runs
from conformance.view.live_cut import LiveCut, live_cut
from conformance.view.segments import Transmission, read_view
from conformance.view.sides import BUS

CHAR = 8.33e-3


def _shape(t: Transmission) -> tuple:
    """A transmission as the judges read it, its events by identity."""

    def ident(e: Event | None) -> int | None:
        return None if e is None else id(e)

    return (
        ident(t.break_event), [id(e) for e in t.chars], [id(e) for e in t.heard],
        ident(t.cut), ident(t.cut_by), t.part,
    )  # fmt: skip


def _shapes(ts: list[Transmission]) -> list[tuple]:
    return [_shape(t) for t in ts]


def _chars(origin: str, t: float, text: str, gap: float = 0.0) -> list[Event]:
    out = []
    for c in text:
        out.append(Event(EventKind.CHAR, origin, t, t + CHAR, wire=to_wire_7e1(ord(c))))
        t += CHAR + gap
    return out


def _break(t: float) -> Event:
    return Event(EventKind.BREAK, TOOL, t, t + 0.013)


def _stimulus(cut: LiveCut, events: list[Event], more: list[Event]) -> list[Transmission] | None:
    mark = cut.mark(events)
    events += more
    return cut.since(events, mark)


def test_a_stimulus_reads_the_one_cut_where_its_own_cut_is_the_same() -> None:
    events: list[Event] = [_break(0.0), *_chars(TOOL, 0.02, "0!"), *_chars(DUT, 0.05, "0\r\n")]
    cut = LiveCut()
    more = [_break(0.2), *_chars(TOOL, 0.22, "0I!"), *_chars(DUT, 0.26, "013TEST\r\n")]
    more += _chars(TOOL, 0.5, "0I!")  # a retry, no break, unanswered
    shared = _stimulus(cut, events, more)
    assert shared is not None and len(shared) == 2
    assert _shapes(shared) == _shapes(read_view(more).transmissions)
    assert shared[0] is cut.cut.transmissions[1]  # the cut's own objects


def test_a_character_going_on_with_the_transmission_before_is_cut_on_its_own() -> None:
    events: list[Event] = [_break(0.0), *_chars(TOOL, 0.02, "0M")]  # no '!' yet
    cut = LiveCut()
    more = _chars(TOOL, 0.02 + 2 * CHAR, "!")
    assert _stimulus(cut, events, more) is None
    assert read_view(more).transmissions[0].text == "!"  # what the stimulus alone reads


def test_a_break_from_before_the_stimulus_is_not_its_own() -> None:
    events: list[Event] = [_break(0.0)]
    cut = LiveCut()
    more = _chars(TOOL, 0.03, "0!")
    assert _stimulus(cut, events, more) is None
    assert read_view(more).transmissions[0].break_event is None


def test_a_frame_cut_into_from_before_the_stimulus_is_not_its_own() -> None:
    events: list[Event] = [*_chars(TOOL, 0.0, "0!"), *_chars(DUT, 0.03, "0+1")]  # no LF
    cut = LiveCut()
    more = _chars(TOOL, events[-1].end + 0.5e-3, "0!")  # within a character gap of it
    shared_cut = read_view(events + more).transmissions[-1].cut
    assert shared_cut is events[-1]  # the whole cut says it cut into that frame
    assert _stimulus(cut, events, more) is None
    assert read_view(more).transmissions[0].cut is None  # the stimulus alone does not


@pytest.mark.parametrize("odd", ["out of order", "capture"])
def test_events_out_of_order_or_a_captures_are_cut_whole_as_before(odd) -> None:
    events: list[Event] = [_break(0.0), *_chars(TOOL, 0.02, "0!")]
    transcript = Transcript(events)
    cut = live_cut(transcript)
    assert cut.mark(events).cut
    if odd == "out of order":
        late = _chars(DUT, 0.0, "0")  # stamped before the command
    else:
        late = [Event(EventKind.CHAR, BUS, 1.0, 1.0 + CHAR, wire=to_wire_7e1(ord("0")))]
    events += late
    assert cut.since(events, cut.mark(events)) is None
    assert not cut.whole
    whole = runs.transcript_view(transcript)
    fresh = read_view(events)
    assert _shapes(whole.transmissions) == _shapes(fresh.transmissions)
    assert whole.undirected == fresh.undirected


def test_the_whole_view_is_read_views_and_keeps_its_length() -> None:
    events: list[Event] = [_break(0.0), *_chars(TOOL, 0.02, "0!"), *_chars(DUT, 0.05, "0\r\n")]
    transcript = Transcript(events)
    cut = live_cut(transcript)
    _stimulus(cut, events, [_break(0.2), *_chars(TOOL, 0.22, "0I!")])
    view = runs.transcript_view(transcript)
    fresh = read_view(events)
    assert _shapes(view.transmissions) == _shapes(fresh.transmissions)
    assert [list(map(id, x)) for x in (view.breaks, view.chars, view.unanswerable)] == [
        list(map(id, x)) for x in (fresh.breaks, fresh.chars, fresh.unanswerable)
    ]
    before = len(view.transmissions)
    events += _chars(TOOL, 0.6, "0!")
    assert len(runs.transcript_view(transcript).transmissions) == before + 1
    assert len(view.transmissions) == before  # a view given stays as it was


@pytest.mark.parametrize(
    "fault",
    [
        "",
        "replies-after-retry",
        "chatter-before-service-request",
        "early-address",
        "inter-char-gap",
        "stray-after-line-end",
    ],
)
def test_every_stimulus_of_a_sim_run_reads_what_its_own_cut_gives(fault, tmp_path: Path) -> None:
    """A sensor run on the sim: each stimulus's transmissions (where the one cut gives them)
    and the whole-run view are those ``read_view`` gives of the same events."""
    compared = {"shared": 0, "alone": 0}
    rebuilt = session_module.SensorSession._rebuilt
    views = []

    def checked(self, mark):
        transcript = self.link.transcript
        shared = live_cut(transcript).since(transcript.events, mark)
        if shared is None:
            compared["alone"] += 1
        else:
            compared["shared"] += 1
            fresh = read_view(transcript.since(mark.first)).transmissions
            assert _shapes(shared) == _shapes(fresh)
        return rebuilt(self, mark)

    transcript_view = runs.transcript_view

    def whole(transcript):
        view = transcript_view(transcript)
        views.append(
            (_shapes(view.transmissions), _shapes(read_view(transcript.events).transmissions))
        )
        return view

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(session_module.SensorSession, "_rebuilt", checked)
        patch.setattr(runs, "transcript_view", whole)
        live_run(tmp_path / "live", f"sim://?faults={fault}" if fault else "sim://")
    assert compared["shared"] > 300  # the one cut is what nearly every stimulus reads
    assert views and all(a == b for a, b in views)


def test_notes_among_the_events_fed_are_left_out_as_read_view_leaves_them() -> None:
    """The events fed after a look are the transcript's own slice unless a NOTE is among
    them (live27): then they are fed without it, as ``read_view`` cuts them; either way the
    cut is ``read_view``'s, and a stimulus whose events hold a NOTE reads the one cut."""
    events: list[Event] = [_break(0.0), *_chars(TOOL, 0.02, "0!"), *_chars(DUT, 0.05, "0\r\n")]
    cut = LiveCut()
    note = Event(EventKind.NOTE, TOOL, 0.25, 0.25, text="a collision")
    more = [_break(0.2), *_chars(TOOL, 0.22, "0I!"), note, *_chars(DUT, 0.26, "013TEST\r\n")]
    shared = _stimulus(cut, events, more)
    assert shared is not None and len(shared) == 1
    assert _shapes(shared) == _shapes(read_view(more).transmissions)
    more = [*_chars(TOOL, 0.6, "0!"), *_chars(DUT, 0.63, "0\r\n")]  # no NOTE: the slice
    assert _shapes(_stimulus(cut, events, more)) == _shapes(read_view(more).transmissions)
    assert _shapes(cut.view().transmissions) == _shapes(read_view(events).transmissions)
