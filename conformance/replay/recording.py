"""A run's saved ``transcript.jsonl`` read back, with the options the run was made with.

A run writes its transcript as JSON lines (:meth:`conformance.transcript.Transcript.write_jsonl`);
this module is the other half. The first line of a transcript written since the replay exists
is a NOTE holding the run's options (``run-options {...}``), so ``sdi12-conform judge`` can
repeat the run's stimuli exactly (same address discovery, same forced version, same selection)
without the user remembering them. Older transcripts lack it; then ``verdicts.json`` beside the
transcript and the command line fill in what they can.
"""

from __future__ import annotations

import heapq
import json
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from operator import attrgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..capture.errors import CaptureError
from ..capture.transcript_io import read_transcript_jsonl
from ..transcript import TOOL, Event, EventKind, Transcript

if TYPE_CHECKING:
    from ..capture.columns import WireColumns

#: Prefix of the NOTE that carries the run's options (first line of a transcript).
OPTIONS_NOTE = "run-options "


class RecordingError(ValueError):
    """A recording that cannot be judged; the message names the file and what is wrong."""


class Recording:
    """The events of one saved run and what is known of how it was made: ``options`` the
    RunOptions fields as saved, ``verdicts`` the verdicts.json beside it (when there is one),
    ``held`` a decoded capture held as columns (:func:`hold_capture`), whose events are
    made only when :attr:`events` is read (a replay reads the columns)."""

    def __init__(
        self,
        path: Path,
        events: list[Event] | None,
        options: dict[str, Any] | None = None,
        verdicts: dict[str, Any] | None = None,
        held: HeldCapture | None = None,
    ) -> None:
        if events is None and held is None:
            raise ValueError("a recording needs its events or its held capture")
        self.path = path
        self._events = events
        self.options: dict[str, Any] = {} if options is None else options
        self.verdicts = verdicts
        self.held = held

    @property
    def events(self) -> list[Event]:
        """Every event, notes too, in the file's order."""
        if self._events is None:
            assert self.held is not None
            self._events = self.held.events()
        return self._events

    @property
    def role(self) -> str | None:
        if "role" in self.options:
            return str(self.options["role"])
        if self.verdicts:
            return self.verdicts.get("run", {}).get("role")
        return None

    @property
    def original_port(self) -> str | None:
        if "port" in self.options:
            return str(self.options["port"])
        if self.verdicts:
            return self.verdicts.get("run", {}).get("port")
        return None

    def wire_events(self) -> list[Event]:
        return [e for e in self.events if e.kind is not EventKind.NOTE]


def options_note(options: dict[str, Any], time: float = 0.0) -> Event:
    """The NOTE a run writes first, so its transcript can be judged again as it was made."""
    return Event(EventKind.NOTE, TOOL, time, time, text=OPTIONS_NOTE + json.dumps(options))


def transcript_path(path: Path) -> Path:
    """``path`` itself, or the ``transcript.jsonl`` inside a run folder."""
    return path / "transcript.jsonl" if path.is_dir() else path


def read_recording(path: str | Path) -> Recording:
    """Read a run's transcript (a ``transcript.jsonl`` or the run folder holding it)."""
    file = transcript_path(Path(path))
    held = _HELD.get(str(file.resolve())) if _HELD else None
    if isinstance(held, HeldCapture):
        options = _options_of(file, held.notes)
        if not len(held.wire):
            raise RecordingError(f"{file}: no bus events in it: nothing to judge")
        return Recording(file, None, options, _verdicts_beside(file), held=held)
    if held is not None:
        events = list(held)
    elif not file.exists():
        raise RecordingError(f"{file}: no such file")
    else:
        try:
            events = _read_events(file)
        except CaptureError as exc:
            raise RecordingError(str(exc)) from None
    options = _options_of(file, events)
    if not any(e.kind is not EventKind.NOTE for e in events):
        raise RecordingError(f"{file}: no bus events in it: nothing to judge")
    return Recording(file, events, options, _verdicts_beside(file))


def _options_of(file: Path, events: list[Event]) -> dict[str, Any]:
    """The options of the first run-options note among ``events`` ({}: none)."""
    for number, event in enumerate(events, 1):
        if event.kind is EventKind.NOTE and event.text.startswith(OPTIONS_NOTE):
            return _options_from(file, number, event.text[len(OPTIONS_NOTE) :])
    return {}


#: the last few transcripts read, by (path, mtime, size): one judging reads its recording up
#: to four times (plan, port check, replay link, plugin), and an hour of bus is 10^6 lines
_READ: dict[tuple[str, int, int], tuple[Event, ...]] = {}


def _read_events(file: Path) -> list[Event]:
    """The transcript's events (a fresh list each call; the events themselves are frozen)."""
    key = _file_key(file)
    if key not in _READ:
        _keep(key, tuple(read_transcript_jsonl(str(file))))
    return list(_READ[key])


def _file_key(file: Path) -> tuple[str, int, int]:
    st = file.stat()
    return (str(file.resolve()), st.st_mtime_ns, st.st_size)


def _keep(key: tuple[str, int, int], events: tuple[Event, ...]) -> None:
    if len(_READ) >= 2:
        _READ.pop(next(iter(_READ)))
    _READ[key] = events


_START = attrgetter("start")


@dataclass
class HeldCapture:
    """A decoded capture handed to its replay in memory as columns (:func:`hold_capture`):
    its run's notes, sorted by start, and the decoded events (no note among them), their
    starts never decreasing. Its events are the notes and the decoded events sorted by
    start, the notes first among equal starts: ``sorted([*notes, *decoded], key=start)``,
    what ``judge`` writes as the capture's ``capture.jsonl``."""

    notes: list[Event]
    wire: WireColumns

    def events(self) -> list[Event]:
        """The notes and the decoded events, made, in the file's order."""
        return list(heapq.merge(self.notes, self.wire.events(), key=_START))

    def largest_uncertainty(self) -> float | None:
        """The largest uncertainty any event carries, when it is a positive number (which
        one of equal values is then immaterial); None: read it from :meth:`events`."""
        wire = self.wire
        values = [n.uncertainty for n in self.notes]
        values += [e.uncertainty for e in wire.made.values()]
        if len(wire.made) < len(wire):
            values.append(wire.uncertainty)  # every certified character's
        if not values or any(v != v for v in values):
            return None  # a NaN's place among the events decides max()
        found = max(values)
        return found if found > 0 else None


#: recordings handed over in memory (:func:`hold_recording`, :func:`hold_capture`), by the
#: file they stand for
_HELD: dict[str, tuple[Event, ...] | HeldCapture] = {}


def hold_recording(path: Path, events: list[Event]) -> None:
    """Let :func:`read_recording` of ``path`` give ``events`` with no file written, until
    :func:`held_recordings` ends: for a decoded capture that is judged straight away and
    deleted (a fault-matrix row's round trip, issue 22: writing its 10^4..10^5 lines was 3%
    of the row's CPU). A user's ``judge`` writes its capture.jsonl, as before."""
    _HELD[str(transcript_path(Path(path)).resolve())] = tuple(events)


def hold_capture(path: Path, notes: list[Event], wire: WireColumns) -> bool:
    """:func:`hold_recording` of a decoded capture whose events are kept as columns (issue
    22: a fault-matrix row's ~2*10^4 characters, whose replay reads only the columns),
    ``notes`` its run's notes: held, and True, when the recording is what
    ``hold_recording(path, sorted([*notes, *wire.events()], key=start))`` would hold (every
    field of the plain type a file reads back as, the decoded starts in order, no NaN
    start among the notes); else nothing is held and False (the caller makes the events)."""
    if not (wire.in_start_order() and wire.plain()):
        return False
    from ..transcript import plain_fields

    if not all(n.start == n.start and plain_fields(n) for n in notes):
        return False
    _HELD[str(transcript_path(Path(path)).resolve())] = HeldCapture(sorted(notes, key=_START), wire)
    return True


@contextmanager
def held_recordings() -> Iterator[None]:
    """What :func:`hold_recording` holds while this lasts is let go at its end."""
    try:
        yield
    finally:
        _HELD.clear()


def options_in(notes: list[Event]) -> dict[str, Any]:
    """The run options in a run's notes ({} when there are none or they are not readable)."""
    for e in notes:
        if e.kind is EventKind.NOTE and e.text.startswith(OPTIONS_NOTE):
            try:
                found = json.loads(e.text[len(OPTIONS_NOTE) :])
            except ValueError:
                return {}
            return found if isinstance(found, dict) else {}
    return {}


def write_recording(path: Path, events: list[Event], *, keep: bool = True) -> None:
    """A transcript file holding ``events`` (a run's, or a decoded capture with its run's
    notes). What is written is also kept as its reading, when reading it back would give
    the same events: a capture round trip reads both files it writes straight away, and a
    run's 10^5 lines cost a second to parse. ``keep`` False: written only (no copy of the
    events made or kept), for a file nothing in this process reads back."""
    if not keep:
        Transcript(events).write_jsonl(str(path))
        return
    events = list(events)
    # floats print as their shortest repr, which reads back bit for bit; an int time would
    # come back a float, so only events of exactly the plain types (the writer says whether
    # all were) stand for their reading
    if Transcript(events).write_jsonl(str(path)):
        _keep(_file_key(Path(path)), tuple(events))


def _options_from(file: Path, number: int, text: str) -> dict[str, Any]:
    try:
        found = json.loads(text)
    except ValueError:
        raise RecordingError(f"{file}, line {number}: the run-options note is not JSON") from None
    if not isinstance(found, dict):
        raise RecordingError(f"{file}, line {number}: the run-options note is not an object")
    return found


def _verdicts_beside(file: Path) -> dict[str, Any] | None:
    beside = file.with_name("verdicts.json")
    if not beside.exists():
        return None
    try:
        found = json.loads(beside.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError):
        return None
    return found if isinstance(found, dict) else None
