"""What the monitor shows: the bus's traffic cut into lines, each with its direction, the time
since the line before and the rules it visibly breaks (sans-I/O).

The events come in as the reader stamps them. A line is shown once the bus has been quiet
after it long enough that no further character can still belong to it (``settle``), so a
reply is shown whole. Directions come from the protocol
(:func:`~conformance.view.direction.infer_directions`): each run it reads is one line (a
break, a command, a reply line, a service request). Direction inference reads forward only,
so a line's direction never changes once shown; it is re-read from the last break before the
lines still to show, which keeps every poll short however long the monitor runs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from ..protocol.timing import CHAR_TIME
from ..transcript import Event, EventKind, decode_7e1, escape
from ..view.direction import Direction, infer_directions
from ..view.sides import RECORDER, SENSOR
from .checks import Context, Flag, command_flags, reply_flags, unsolicited_flags

#: Quiet after a line's last stop bit before it is shown (s): longer than any pause inside a
#: reply that the stamps may show (a batch of a USB adapter's latency timer), short enough to
#: feel live.
SETTLE = 3 * CHAR_TIME


@dataclass(frozen=True)
class BusLine:
    """One line of traffic as the monitor shows it."""

    kind: str  # "break" or "chars"
    start: float
    end: float
    side: str | None  # RECORDER, SENSOR, or None (unknown)
    sure: bool
    how: str  # the protocol cue the direction rests on
    text: str  # escaped wire text ("" for a break)
    gap: float | None  # s since the previous line's end (None: the first line)
    flags: tuple[Flag, ...] = ()

    @property
    def who(self) -> str:
        name = {RECORDER: "recorder", SENSOR: "sensor"}.get(self.side or "", "unknown")
        return name if self.sure or self.side is None else f"{name}?"

    def plain(self) -> str:
        """The line as one plain text line (off a terminal, in CI logs)."""
        since = "" if self.gap is None else f" +{self.gap * 1e3:.1f} ms"
        what = "BREAK" if self.kind == "break" else f"'{self.text}'"
        text = f"{self.start:10.4f} s{since:>13}  {self.who:<9} {what}"
        for flag in self.flags:
            text += f"  !! {flag}"
        return text


@dataclass
class LineTracker:
    """Turns the events heard so far into shown lines, one poll at a time.

    A reply's start is flagged only where the run's own uncertainty cannot excuse it: the
    final judging (``judge`` on the transcript) weighs every stamp with the largest
    uncertainty any event of the recording carries, and a stamp made before the link saw the
    burst that held it back carries only the declared floor. So a line is judged with the
    larger of its own stamps' figure, the largest any event heard so far carries (``worst``)
    and what the link measures over the span by the time the line is shown (``between``, the
    link's ``uncertainty_between``; None: the events' figures only). On the reference
    emulator the live view flagged a 21.28 ms start with the declared ±5 ms while the run
    measured ±30.1 ms and its verdict found no FAIL.
    """

    settle: float = SETTLE
    between: Callable[[float, float], float] | None = None
    events: list[Event] = field(default_factory=list)  # from the inference's anchor on
    lines: int = 0  # lines shown so far
    chars: int = 0
    breaks: int = 0
    flagged: int = 0  # shown lines that break a rule
    worst: float = 0.0  # s: the largest uncertainty an event heard so far carries
    _anchor: int = 0  # index of the break the next inference starts from
    _shown_until: float = float("-inf")  # end of the last shown line
    _context: Context = field(default_factory=Context)

    def add(self, events: list[Event]) -> None:
        for e in events:
            if e.kind is EventKind.NOTE:
                continue
            self.events.append(e)
            self.worst = max(self.worst, e.uncertainty)
            self.chars += e.kind is EventKind.CHAR
            self.breaks += e.kind is EventKind.BREAK

    def poll(self, now: float, *, final: bool = False) -> list[BusLine]:
        """The lines that are complete by ``now`` (all of them when ``final``), not shown yet."""
        window = self.events[self._anchor :]
        if not window:
            return []
        new: list[BusLine] = []
        for run, direction in _lines(infer_directions(window)):
            if run[-1].end <= self._shown_until + 1e-12:
                continue  # shown by an earlier poll
            if not final and run[-1].end > now - self.settle:
                break  # may still grow
            line = self._line(run, direction)
            new.append(line)
            self._shown_until = run[-1].end
        self.lines += len(new)
        self.flagged += sum(1 for line in new if line.flags)
        self._move_anchor()
        return new

    def _move_anchor(self) -> None:
        """Start the next inference at the last break already shown, and forget the events
        before it (the transcript on disk keeps them): memory stays bounded however long the
        monitor runs."""
        for k in range(len(self.events) - 1, self._anchor - 1, -1):
            e = self.events[k]
            if e.kind is EventKind.BREAK and e.end <= self._shown_until + 1e-12:
                del self.events[:k]
                self._anchor = 0
                return

    def _line(self, run: list[Event], d: Direction) -> BusLine:
        previous = self._shown_until
        gap = None if previous == float("-inf") else run[0].start - previous
        if run[0].kind is EventKind.BREAK:
            self._context.command_end = None
            return BusLine("break", run[0].start, run[-1].end, d.side, d.sure, d.how, "", gap)
        text = decode_7e1(run)
        if d.side == RECORDER:
            flags = command_flags(text, self._context, run)
        elif d.side == SENSOR and self._context.command_end is not None:
            flags = reply_flags(text, self._context, run, self._measured(run[0].start))
        elif d.side == SENSOR:
            flags = unsolicited_flags(text, run)
        else:
            flags = []
        return BusLine(
            "chars",
            run[0].start,
            run[-1].end,
            d.side,
            d.sure,
            d.how,
            escape(text),
            gap,
            tuple(flags),
        )

    def _measured(self, reply_start: float) -> float:
        """The run's uncertainty for the gap from the command being answered to a reply
        starting at ``reply_start`` (s): see the class docstring."""
        u = self.worst
        last = self._context.command_last
        if self.between is not None and last is not None:
            u = max(u, self.between(last.end, reply_start))
        return u


def _lines(directed: list[tuple[Event, Direction]]) -> list[tuple[list[Event], Direction]]:
    """Consecutive events that share one Direction (one run read by the inference) are one
    line; a sensor's run is cut after each LF (one reply line each); a break is its own."""
    out: list[tuple[list[Event], Direction]] = []
    for e, d in directed:
        if out and e.kind is not EventKind.BREAK and out[-1][1] is d:
            run = out[-1][0]
            if run[0].kind is not EventKind.BREAK and not (
                d.side == SENSOR and run[-1].char7 == 0x0A
            ):
                run.append(e)
                continue
        out.append(([e], d))
    return out
