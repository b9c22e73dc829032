"""A live run's transcript cut once, as it grows, for both readers of the cut.

A live sensor run reads the role-neutral view (:func:`~.segments.read_view`) twice over:
each stimulus's records are rebuilt from the view of the events it left
(:meth:`~conformance.sensor.session.SensorSession._rebuilt`, some 900 stimuli a run), and
the whole-run cases and the reports read the view of the whole transcript
(:func:`~.runs.transcript_view`). Each cut read every event again (issue 22: 16 + 19 ms of
a fault-matrix row's CPU). :class:`LiveCut` feeds a :class:`~.segments.Cut` the events
added since it last looked, so every event is cut once, and hands both readers the one
cut's :class:`~.segments.Transmission` objects where they are what a cut of their own
events would give:

- the whole transcript's view: whenever every event so far came in time order (what
  ``read_view`` sorts them into) and none is a capture's (origin :data:`~.sides.BUS`,
  whose direction the protocol decides over the whole recording); else nobody is fed
  again and the readers cut as before;
- the view of the events since a stimulus began (:meth:`LiveCut.mark` where it begins,
  :meth:`LiveCut.since` after it): the cut's last transmissions, those that began there,
  unless the cut of those events alone would start otherwise: a character of theirs went
  on with a transmission from before, or the first one's break or a frame it cut into
  (:attr:`Transmission.cut`) came before them. Those stimuli are cut on their own, as
  before.
"""

from __future__ import annotations

from itertools import repeat
from math import inf
from operator import attrgetter, eq, ge
from typing import NamedTuple

from ..transcript import TOOL, Event, EventKind, Transcript
from .segments import Cut, TranscriptView, Transmission
from .sides import BUS

_START = attrgetter("start")
_ORIGIN = attrgetter("origin")
_KIND = attrgetter("kind")
#: a module constant: a member read off the enum goes through its metaclass's ``__getattr__`` hook
#: on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_NOTE = EventKind.NOTE


class LiveCut:
    """The transcript's events cut as they come (:mod:`.live_cut`)."""

    def __init__(self) -> None:
        self.cut = Cut()
        self.source: list[Event] | None = None  # the transcript's list of events
        self.fed = 0  # how many of its events were looked at
        self.last_start = -inf  # the start of the last event fed
        #: every event so far was fed: in time order, none a capture's
        self.whole = True

    def advance(self, events: list[Event]) -> bool:
        """Feed the events added since the last look; whether the cut holds them all."""
        if self.source is None:
            self.source = events
        elif events is not self.source:  # another list: the events fed may not be in it
            self._give_up()
        if not self.whole or self.fed == len(events):
            return self.whole
        note = _NOTE
        new = events[self.fed :]
        if note in map(_KIND, new):  # (a NOTE among them: rare; looked for in C)
            new = [e for e in new if e.kind is not note]
        self.fed = len(events)
        if not new:
            return True
        starts = list(map(_START, new))
        # in time order (equal starts keep their order, as the stable sort does), from
        # where the last batch ended; a NaN start is in no order
        in_order = starts[0] >= self.last_start and all(map(ge, starts[1:], starts))
        if not in_order or BUS in map(_ORIGIN, new):
            self._give_up()
            return False
        self.last_start = starts[-1]
        self.cut.feed(new, map(eq, map(_ORIGIN, new), repeat(TOOL)))
        return True

    def _give_up(self) -> None:
        self.whole = False
        self.cut = Cut()  # nothing reads it again: its events are not held twice

    def view(self) -> TranscriptView:
        """The whole transcript's view (:meth:`advance` first) as ``read_view`` gives it:
        lists of its own (the cut goes on growing), the transmissions the cut's."""
        cut = self.cut
        return TranscriptView(
            list(cut.transmissions), list(cut.breaks), list(cut.chars), list(cut.unanswerable)
        )

    def mark(self, events: list[Event]) -> Mark:
        """Where a stimulus begins: the transcript's length, and what the cut holds there
        (:meth:`since` tells from it which transmissions began after it)."""
        first = len(events)
        if not self.advance(events):
            return Mark(first)
        cut = self.cut
        current = cut._current
        chars = len(current.chars) if current is not None else 0
        return Mark(
            first, True, len(cut.transmissions), current, chars, cut._pending, cut._last_heard
        )

    def since(self, events: list[Event], mark: Mark) -> list[Transmission] | None:
        """The transmissions ``read_view(events[mark.first:])`` gives, as the cut's own
        objects, or None where that cut would start otherwise (:mod:`.live_cut`). What the
        cut held at the mark is all that can make them differ: the transmission still open
        there (a character after the mark that went on with it), the break no character had
        followed yet (the first new transmission's break would be one from before the
        events) and the sensors' last character (a frame a new transmission cut into,
        :attr:`Transmission.cut`, from before them: any later one is among them)."""
        if not mark.cut or not self.advance(events):
            return None
        current = mark.current
        if current is not None and len(current.chars) != mark.chars:
            return None  # a character of theirs went on with the transmission from before
        began = self.cut.transmissions[mark.transmissions :]
        if began and mark.pending is not None and began[0].break_event is mark.pending:
            return None  # the break before the first came before these events
        heard = mark.last_heard
        if heard is not None and any(t.cut is heard for t in began):
            return None  # the frame it cut into began before these events
        return began


class Mark(NamedTuple):
    """:meth:`LiveCut.mark`: the transcript's length where a stimulus began and, where the
    cut held every event to there (``cut``), its state then. A named tuple: made once per
    stimulus, read by name, never changed (a frozen dataclass set its seven fields one
    ``object.__setattr__`` call at a time)."""

    first: int
    cut: bool = False
    transmissions: int = 0  # how many the cut held
    current: Transmission | None = None  # the one still open (the cut's)
    chars: int = 0  # its characters then
    pending: Event | None = None  # the recorder's break no character had followed yet
    last_heard: Event | None = None  # the sensors' last character so far


def live_cut(transcript: Transcript) -> LiveCut:
    """The transcript's :class:`LiveCut`, made at the first question: by a live session's
    first stimulus (:func:`~.runs.transcript_view` reads it where one was made; a loaded
    recording, which nobody cuts as it grows, is cut whole as before)."""
    found = transcript.__dict__.get("_live_cut")
    if found is None:
        found = transcript.__dict__["_live_cut"] = LiveCut()
    return found


__all__ = ["LiveCut", "Mark", "live_cut"]
