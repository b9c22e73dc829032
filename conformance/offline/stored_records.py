"""A sensor pass's records with their events as positions into the loaded store (issue 22:
one hour of a busy capture judged in bounded memory).

The sensor pass (:func:`~.sensor_windows.sensor_records`) keeps a sensor's exchanges and
measurements for its whole run: the measurement, data, identification and extended cases
judge them. Their lists of events (a command's characters, a reply's, the strays before a
try, the characters heard while a measurement waited) were the window's events as objects,
~150 bytes each with their two stamps: a tenth of an hour's capture a sensor, 4.3 MB held
through its run, the growth left in a passive judgement's peak (memory18). Once a window's
records are made, each such list becomes a :class:`~conformance.event_store.StoredEvents`
over the store the window was read from, its events made again when a case reads them (the
few it reads: reply texts are kept, timing and evidence are read of the exchanges that
matter). A list holding an event that is not one of the window's, or a recording not
held as a compact store, is left as it is.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ..event_store import CompactEvents, StoredEvents
from ..tool_recorder.records import Attempt, Exchange, Measurement
from ..transcript import Event


class Positions:
    """Where each of a window's events is in the store: ``lo`` the first's position,
    ``window`` the events in the store's order (the very objects the records hold)."""

    def __init__(self, store: CompactEvents, lo: int, window: Sequence[Event]) -> None:
        self.store = store
        self.at = {id(e): lo + k for k, e in enumerate(window)}
        self.window = window  # held while ``at`` is read: the ids stay theirs

    def stored(self, events: list[Event]) -> Sequence[Event]:
        """``events`` as a :class:`StoredEvents` (``events`` itself where it is empty or
        holds an event that is not the window's)."""
        if not events:
            return events
        at = self.at
        try:
            positions = [at[id(e)] for e in events]
        except KeyError:
            return events
        return StoredEvents(self.store, positions)


def store_records(
    positions: Positions, exchanges: Iterable[Exchange], measurements: Iterable[Measurement]
) -> None:
    """Each of the records' lists of events held as positions (see the module's docstring):
    the exchanges (a measurement's own and its data's among them, each once) and the
    measurements' waits. What every record reads is unchanged, its reply text kept."""
    seen: set[int] = set()
    for x in exchanges:
        _store_exchange(positions, x, seen)
    for m in measurements:
        for x in (m.start, *m.data):
            _store_exchange(positions, x, seen)
        m.waited_events = positions.stored(m.waited_events)  # type: ignore[assignment]


def _store_exchange(positions: Positions, x: Exchange, seen: set[int]) -> None:
    if id(x) in seen:
        return
    seen.add(id(x))
    for a in x.attempts:
        _store_attempt(positions, a)
    x.heard_late = positions.stored(x.heard_late)  # type: ignore[assignment]


def _store_attempt(positions: Positions, a: Attempt) -> None:
    text = a.reply_text  # (decoded once, of the list: kept with the stored sequence)
    a.command_events = positions.stored(a.command_events)  # type: ignore[assignment]
    a.reply_events = positions.stored(a.reply_events)  # type: ignore[assignment]
    a.stray_events = positions.stored(a.stray_events)  # type: ignore[assignment]
    a.knows_reply_text(text)
