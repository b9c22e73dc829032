"""Inline SVG timing diagrams of an exchange, for the timing cases of the HTML report.

A certifier reading "response start 16.2 ms, allowed <= 15.40 ms" wants to *see* the exchange:
the break, the marking after it, the command characters, the reply characters and the window
the reply had to start in. The diagram is drawn from the case's wire events (the same ones the
judges read), so it can never disagree with the verdict. Long idle stretches (a ttt wait, the
150 ms of marking before a probe) are cut out of the time axis and labelled with their length,
or a 2 s measurement would squeeze every character into a hair line.

The SVG is self-contained (no script, no external reference) and every text that came from the
DUT goes through :func:`html.escape`: the device is untrusted (design.md 7).
"""

from __future__ import annotations

from array import array
from bisect import bisect_left, bisect_right
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from html import escape
from itertools import pairwise, repeat

from ..judges.wire import Segment, segments
from ..protocol.framing import COMMAND_END, CR, ETX, LF, STX
from ..protocol.timing import (
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    NO_BREAK_WINDOW,
    RESPONSE_START_MAX,
    RESPONSE_START_MIN,
    STANDBY_MARKING,
    TOLERANCE,
)
from ..transcript import TOOL, Event, EventKind, Transcript
from ..transcript import escape as escape_wire
from ..verdicts import Finding
from ..view.runs import LazyCut, whole_cut
from ..view.segments import memo

PX_PER_MS = 5.0  # one 8.33 ms character is 42 px: room for "CR"/"LF" at reading size
ELIDE_OVER = 0.14  # s: idle stretches longer than this are cut out of the axis
ELIDED_PX = 64
LEFT = 84  # px for the lane names
PAD_BEFORE, PAD_AFTER = 0.004, 0.018  # s around each cluster (the window ends 15.4 ms late)
MAX_EVENTS = 240  # a diagram is for reading one exchange, not a whole run
GAP_SHOWN = 0.05e-3  # s: character gaps shorter than this are not annotated

# rows (y of the top edge) and lane height
Y_LEGEND, Y_TOP_LABEL, Y_TOOL, Y_MID_LABEL, Y_DUT, Y_GAP_LABEL, Y_LINE, Y_AXIS = (
    16,
    46,
    54,
    102,
    114,
    160,
    172,
    212,
)
LANE_H = 28
LINE_H = 12  # the "line after a reply" lane: the 87 ms and 100 ms windows
HEIGHT = 246
FONT = 13  # labels; glyphs in the lanes are larger
#: after a reply the axis keeps this much of the line drawn, so the windows show
AFTER_REPLY = STANDBY_MARKING + 4e-3

COLOURS = {
    "tool": "#1565c0",
    "dut": "#2e7d32",
    "break": "#b26a00",
    "window": "#43a047",
    "bad": "#c62828",
    "axis": "#555",
    "follow": "#7e57c2",
}


@dataclass(frozen=True)
class _Piece:
    """A stretch of time drawn linearly, starting at pixel ``x``."""

    start: float
    end: float
    x: float

    @property
    def width(self) -> float:
        return (self.end - self.start) * 1e3 * PX_PER_MS


class Axis:
    """Piecewise-linear time axis: clusters of activity drawn to scale, idle cut out."""

    def __init__(self, events: Sequence[Event], keep_after: Sequence[float] = ()) -> None:
        """``keep_after``: times (reply ends) whose next :data:`AFTER_REPLY` s stay drawn."""
        self.t0 = events[0].start
        spans = sorted(
            [(e.start, e.end) for e in events] + [(t, t + AFTER_REPLY) for t in keep_after]
        )
        clusters: list[list[float]] = []
        for start, end in spans:
            if clusters and start - clusters[-1][1] <= ELIDE_OVER:
                clusters[-1][1] = max(clusters[-1][1], end)
            else:
                clusters.append([start, end])
        self.pieces: list[_Piece] = []
        x = float(LEFT)
        for i, (start, end) in enumerate(clusters):
            if i:
                x += ELIDED_PX
            piece = _Piece(start - PAD_BEFORE, end + PAD_AFTER, x)
            self.pieces.append(piece)
            x += piece.width
        self.width = x + 12

    def x(self, t: float) -> float:
        """Pixel of time ``t``; times inside a cut-out stretch clamp to its edges."""
        for p in self.pieces:
            if t <= p.end:
                return p.x + max(0.0, t - p.start) * 1e3 * PX_PER_MS
        last = self.pieces[-1]
        return last.x + last.width

    def elisions(self) -> list[tuple[float, float]]:
        """(pixel, seconds cut out) for each cut in the axis."""
        return [(b.x - ELIDED_PX / 2, b.start - a.end) for a, b in pairwise(self.pieces)]


def _glyph(e: Event) -> str:
    c = e.char7
    names = {CR: "CR", LF: "LF", STX: "STX", ETX: "ETX", 0x20: "␣"}
    if c in names:
        return names[c]
    return chr(c) if 0x21 <= c <= 0x7E else f"{c:02X}"


def _text(
    x: float, y: float, text: str, *, size: int = 10, anchor: str = "middle", **attrs: str
) -> str:
    extra = "".join(f' {k.replace("_", "-")}="{escape(v)}"' for k, v in attrs.items())
    return (
        f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size}" text-anchor="{anchor}"{extra}>'
        f"{escape(text)}</text>"
    )


def _ms(seconds: float, places: int = 2) -> str:
    return f"{seconds * 1e3:.{places}f} ms"


#: Where a reply must start (R-7.0-09/10): the window the diagram shades after a command.
WINDOW_LO, WINDOW_HI = RESPONSE_START_MIN, RESPONSE_START_MAX + TOLERANCE

LEGEND = (
    ("tool", "recorder → sensor"),
    ("dut", "sensor → recorder"),
    ("break", "break"),
    ("window", f"reply must start in {WINDOW_LO * 1e3:.2f}–{WINDOW_HI * 1e3:.2f} ms"),
    (
        "follow",
        f"after a reply: next command without break ≤ {_ms(NO_BREAK_WINDOW, 0)}; "
        f"standby after {_ms(STANDBY_MARKING, 0)}",
    ),
    ("bad", "out of limits"),
)
LEGEND_WIDTH = LEFT + sum(30 + 6.2 * len(label) for _, label in LEGEND)


def _legend() -> str:
    out, x = [], float(LEFT)
    for key, label in LEGEND:
        opacity = ' fill-opacity="0.25"' if key in ("window", "follow") else ""
        out.append(
            f'<rect x="{x:.0f}" y="{Y_LEGEND - 10}" width="12" height="11" '
            f'fill="{COLOURS[key]}"{opacity}/>'
        )
        out.append(_text(x + 16, Y_LEGEND, label, size=FONT, anchor="start"))
        x += 30 + 6.2 * len(label)
    return "".join(out)


def _lanes(axis: Axis) -> str:
    out = []
    out.append(_text(4, Y_LINE + LINE_H - 1, "line idle", size=FONT - 1, anchor="start"))
    for y, name in ((Y_TOOL, "recorder"), (Y_DUT, "sensor")):
        mid = y + LANE_H / 2
        out.append(_text(4, mid + 5, name, size=14, anchor="start", font_weight="bold"))
        out.append(
            f'<line x1="{LEFT}" y1="{y + LANE_H}" x2="{axis.width - 8:.1f}" y2="{y + LANE_H}" '
            'stroke="#bbb" stroke-width="1"/>'
        )
    return "".join(out)


def _axis(axis: Axis) -> str:
    out = [
        f'<line x1="{LEFT}" y1="{Y_AXIS}" x2="{axis.width - 8:.1f}" y2="{Y_AXIS}" '
        f'stroke="{COLOURS["axis"]}"/>'
    ]
    for p in axis.pieces:
        first = int((p.start - axis.t0) * 1e3 // 10 + 1) * 10
        last_label = -1e9
        for ms in range(first, int((p.end - axis.t0) * 1e3) + 1, 10):
            x = p.x + ((axis.t0 + ms / 1e3) - p.start) * 1e3 * PX_PER_MS
            out.append(
                f'<line x1="{x:.1f}" y1="{Y_AXIS}" x2="{x:.1f}" y2="{Y_AXIS + 4}" '
                f'stroke="{COLOURS["axis"]}"/>'
            )
            if x - last_label >= 60:
                out.append(_text(x, Y_AXIS + 18, f"{ms} ms", size=12, fill=COLOURS["axis"]))
                last_label = x
    for x, cut in axis.elisions():
        for dx in (-4, 4):
            out.append(
                f'<line x1="{x + dx - 3:.1f}" y1="{Y_TOOL - 4}" x2="{x + dx + 3:.1f}" '
                f'y2="{Y_AXIS + 4}" stroke="#999" stroke-dasharray="3 2"/>'
            )
        label = f"{cut:.2f} s" if cut >= 1 else f"{cut * 1e3:.0f} ms"
        out.append(
            f'<rect x="{x - 30:.1f}" y="{Y_MID_LABEL - 26}" width="60" height="32" fill="#fff"/>'
        )
        out.append(_text(x, Y_MID_LABEL - 12, "idle", size=12, fill="#666"))
        out.append(_text(x, Y_MID_LABEL + 2, label, size=12, fill="#666"))
    return "".join(out)


def _char(axis: Axis, e: Event) -> str:
    who = "tool" if e.origin == TOOL else "dut"
    y = Y_TOOL if who == "tool" else Y_DUT
    x0, x1 = axis.x(e.start), axis.x(e.end)
    stroke = COLOURS["bad"] if not e.parity_ok else "#fff"
    glyph = _glyph(e)
    tip = f"{who} {glyph!r} {_ms(e.start - axis.t0)} to {_ms(e.end - axis.t0)}"
    if not e.parity_ok:
        tip += " (parity error)"
    return (
        f'<g><title>{escape(tip)}</title><rect x="{x0:.1f}" y="{y}" '
        f'width="{max(1.0, x1 - x0):.1f}" '
        f'height="{LANE_H}" fill="{COLOURS[who]}" stroke="{stroke}" stroke-width="1"/>'
        + _text((x0 + x1) / 2, y + 20, glyph, size=16 if len(glyph) == 1 else 13, fill="#fff")
        + "</g>"
    )


def _break(axis: Axis, e: Event, following: Event | None) -> str:
    x0, x1 = axis.x(e.start), axis.x(e.end)
    out = [
        f"<g><title>{escape('break ' + _ms(e.duration))}</title>"
        f'<rect x="{x0:.1f}" y="{Y_TOOL}" width="{max(1.0, x1 - x0):.1f}" height="{LANE_H}" '
        f'fill="{COLOURS["break"]}"/></g>',
        _text(
            x0,
            Y_TOP_LABEL,
            f"break {_ms(e.duration)}",
            size=FONT,
            anchor="start",
            fill=COLOURS["break"],
        ),
    ]
    if following is not None and following.start - e.end <= ELIDE_OVER:
        fx = axis.x(following.start)
        marking = following.start - e.end
        out.append(
            f'<path d="M{x1:.1f},{Y_TOOL + LANE_H + 4} v4 H{fx:.1f} v-4" fill="none" '
            f'stroke="{COLOURS["break"]}"/>'
        )
        out.append(
            _text(
                (x1 + fx) / 2,
                Y_MID_LABEL + 2,
                f"marking {_ms(marking)}",
                size=FONT - 1,
                fill=COLOURS["break"],
            )
        )
    return "".join(out)


def _window(axis: Axis, command_end: float, reply: Event | None) -> str:
    """The response-start window after a command (R-7.0-09/10) and where the reply began."""
    x0, x1 = axis.x(command_end + WINDOW_LO), axis.x(command_end + WINDOW_HI)
    out = [
        f"<g><title>reply start window {_ms(WINDOW_LO)} to "
        f"{_ms(WINDOW_HI)} after the command</title>"
        f'<rect x="{x0:.1f}" y="{Y_DUT - 4}" width="{x1 - x0:.1f}" height="{LANE_H + 8}" '
        f'fill="{COLOURS["window"]}" fill-opacity="0.22" stroke="{COLOURS["window"]}" '
        'stroke-dasharray="2 2"/></g>'
    ]
    if reply is not None:
        delay = reply.start - command_end
        ok = WINDOW_LO - 1e-9 <= delay <= WINDOW_HI + 1e-9
        colour = COLOURS["dut"] if ok else COLOURS["bad"]
        rx = axis.x(reply.start)
        out.append(
            f'<line x1="{rx:.1f}" y1="{Y_MID_LABEL - 6}" x2="{rx:.1f}" y2="{Y_DUT + LANE_H}" '
            f'stroke="{colour}" stroke-width="1.5"/>'
        )
        out.append(
            _text(
                rx + 4,
                Y_MID_LABEL - 2,
                f"reply +{_ms(delay)}",
                size=FONT,
                anchor="start",
                fill=colour,
            )
        )
    return "".join(out)


def _gap(axis: Axis, a: Event, b: Event) -> str:
    gap = b.start - a.end
    colour = COLOURS["bad"] if gap > INTER_CHAR_GAP_MAX + 1e-9 else COLOURS["axis"]
    x0, x1 = axis.x(a.end), axis.x(b.start)
    return (
        f'<path d="M{x0:.1f},{Y_DUT + LANE_H + 2} v4 H{x1:.1f} v-4" fill="none" '
        f'stroke="{colour}"/>'
        + _text((x0 + x1) / 2, Y_GAP_LABEL, f"gap {_ms(gap)}", size=FONT - 1, fill=colour)
    )


def _marking_before_commands(axis: Axis, events: Sequence[Event]) -> str:
    """Marking the line carried before each command that no break preceded (the 87 ms and
    100 ms rules turn on it), drawn above the recorder lane."""
    out = []
    for previous, e in pairwise(events):
        starts_command = e.kind is EventKind.CHAR and e.origin == TOOL
        if not starts_command or previous.kind is EventKind.BREAK:
            continue
        tool_char = previous.origin == TOOL and previous.kind is EventKind.CHAR
        if tool_char and previous.char7 != ord(COMMAND_END):
            continue  # inside a command (a gap between its characters is drawn as is)
        idle = e.start - previous.end
        if not 2 * CHAR_TIME <= idle <= ELIDE_OVER:
            continue
        x0, x1 = axis.x(previous.end), axis.x(e.start)
        out.append(
            f'<path d="M{x0:.1f},{Y_TOOL - 2} v-4 H{x1:.1f} v4" fill="none" '
            f'stroke="{COLOURS["axis"]}"/>'
        )
        out.append(_text((x0 + x1) / 2, Y_TOP_LABEL - 4, f"marking {_ms(idle)}", size=FONT - 1))
    return "".join(out)


def _reply_ends(events: Sequence[Event]) -> list[tuple[float, Event | None]]:
    """(end of a sensor reply, the recorder's next event or None): a reply ends where its
    last character is followed by a recorder event, or by nothing."""
    out = []
    for i, e in enumerate(events):
        if e.kind is not EventKind.CHAR or e.origin == TOOL:
            continue
        later = [f for f in events[i + 1 :] if f.kind is not EventKind.NOTE]
        if later and later[0].origin != TOOL:
            continue  # more sensor output follows: not the end of the reply
        out.append((e.end, later[0] if later else None))
    return out


def _after_reply(axis: Axis, end: float, following: Event | None) -> str:
    """The line after a reply: up to 87 ms the recorder may send the next command without a
    break (R-7.0-16/17); after 100 ms of marking the sensor is in standby (R-7.0-15). Drawn
    as a band with both limits marked, and where the recorder's next event came."""
    x0 = axis.x(end)
    x87, x100 = axis.x(end + NO_BREAK_WINDOW), axis.x(end + STANDBY_MARKING)
    colour = COLOURS["follow"]
    out = [
        f"<g><title>after the reply: next command without a break within "
        f"{_ms(NO_BREAK_WINDOW)}; the sensor is in standby after {_ms(STANDBY_MARKING)} of "
        f'marking</title><rect x="{x0:.1f}" y="{Y_LINE}" width="{x87 - x0:.1f}" '
        f'height="{LINE_H}" fill="{colour}" fill-opacity="0.3"/></g>'
    ]
    for x, label, anchor in (
        (x87, _ms(NO_BREAK_WINDOW, 0), "end"),
        (x100, _ms(STANDBY_MARKING, 0), "start"),
    ):
        out.append(
            f'<line x1="{x:.1f}" y1="{Y_LINE - 4}" x2="{x:.1f}" y2="{Y_LINE + LINE_H + 4}" '
            f'stroke="{colour}" stroke-width="2"/>'
        )
        dx = -3 if anchor == "end" else 3
        out.append(
            _text(x + dx, Y_LINE + LINE_H + 16, label, size=FONT - 1, anchor=anchor, fill=colour)
        )
    if following is not None and following.start - end <= AFTER_REPLY:
        fx = axis.x(following.start)
        what = "break" if following.kind is EventKind.BREAK else "next command"
        out.append(
            f'<line x1="{fx:.1f}" y1="{Y_TOOL}" x2="{fx:.1f}" y2="{Y_LINE + LINE_H}" '
            f'stroke="{colour}" stroke-dasharray="4 3"/>'
        )
        out.append(
            _text(
                fx + 3,
                Y_LINE - 3,
                f"{what} +{_ms(following.start - end)}",
                size=FONT - 1,
                anchor="start",
                fill=colour,
            )
        )
    return "".join(out)


def _exchanges(events: Sequence[Event]) -> list[tuple[float, Event | None]]:
    """(command end, first reply character or None) for each command ending in ``!``."""
    found = []
    for i, e in enumerate(events):
        if not (e.kind is EventKind.CHAR and e.origin == TOOL and e.char7 == ord(COMMAND_END)):
            continue
        reply = None
        for f in events[i + 1 :]:
            if f.origin == TOOL and f.kind is not EventKind.NOTE:
                break
            if f.kind is EventKind.CHAR and f.start - e.end <= NO_BREAK_WINDOW:
                reply = f
                break
        found.append((e.end, reply))
    return found


def _widest_gaps(events: Sequence[Event]) -> list[tuple[Event, Event]]:
    """Per run of sensor characters, its widest inter-character gap (if worth showing)."""
    runs: list[list[Event]] = []
    previous: Event | None = None
    for e in events:
        if e.kind is not EventKind.CHAR or e.origin == TOOL:
            previous = None  # the recorder spoke: the next sensor character starts a new run
            continue
        if previous is not None and e.start - previous.end <= 2 * CHAR_TIME:
            runs[-1].append(e)
        else:
            runs.append([e])
        previous = e
    out = []
    for run in runs:
        if len(run) < 2:
            continue
        a, b = max(pairwise(run), key=lambda p: p[1].start - p[0].end)
        if b.start - a.end >= GAP_SHOWN:
            out.append((a, b))
    return out


def wire_title(title: str, events: Iterable[Event]) -> str:
    """``title`` with what the diagram draws of each break and the marking after it, as the
    wire had them. A case's label names its stimulus as asked ("break, 77 ms marking, a!"),
    and a link's latency can put other figures on the wire (89.05 ms); a title that states
    only the asked figure reads as a diagram that contradicts it (issue 19)."""
    drawn = sorted((e for e in events if e.kind is not EventKind.NOTE), key=lambda e: e.start)
    said = []
    for i, e in enumerate(drawn):
        if e.kind is not EventKind.BREAK:
            continue
        command = next((f for f in drawn[i + 1 :] if f.kind is EventKind.CHAR), None)
        if command is not None and command.origin == TOOL and command.start - e.end <= ELIDE_OVER:
            said.append(f"break {_ms(e.duration)}, marking {_ms(command.start - e.end)}")
    if not said:
        return title
    more = f" and {len(said) - WIRE_TITLE_BREAKS} more" if len(said) > WIRE_TITLE_BREAKS else ""
    drawn_text = "; ".join(said[:WIRE_TITLE_BREAKS]) + more
    return f"{title} (drawn as on the wire: {drawn_text})" if title else drawn_text


WIRE_TITLE_BREAKS = 3  # breaks a title spells out


def timing_svg(events: Iterable[Event], title: str = "") -> str:
    """An inline SVG of ``events`` (breaks and characters; notes are skipped), or "" if none."""
    drawn = [e for e in events if e.kind is not EventKind.NOTE]
    drawn.sort(key=lambda e: e.start)
    if not drawn:
        return ""
    note = ""
    if len(drawn) > MAX_EVENTS:
        note = f"first {MAX_EVENTS} of {len(drawn)} bus events drawn"
        drawn = drawn[:MAX_EVENTS]
    ends = _reply_ends(drawn)
    axis = Axis(drawn, [end for end, _next in ends])
    parts = [_legend(), _lanes(axis)]
    for end, following in ends:
        parts.append(_after_reply(axis, end, following))
    for end, reply in _exchanges(drawn):
        parts.append(_window(axis, end, reply))
    for i, e in enumerate(drawn):
        if e.kind is EventKind.BREAK:
            following = next(
                (f for f in drawn[i + 1 :] if f.kind is EventKind.CHAR and f.origin == TOOL), None
            )
            parts.append(_break(axis, e, following))
        else:
            parts.append(_char(axis, e))
    parts.append(_marking_before_commands(axis, drawn))
    for a, b in _widest_gaps(drawn):
        parts.append(_gap(axis, a, b))
    parts.append(_axis(axis))
    if note:
        parts.append(_text(axis.width - 10, HEIGHT - 4, note, size=12, anchor="end", fill="#666"))
    label = escape(wire_title(title, drawn) or "timing diagram")
    width = max(axis.width, LEGEND_WIDTH)
    return (
        f'<svg class="sdi12-timing" xmlns="http://www.w3.org/2000/svg" role="img" '
        f'aria-label="{label}" width="{width:.0f}" height="{HEIGHT}" '
        f'viewBox="0 0 {width:.0f} {HEIGHT}" font-family="sans-serif">'
        f"<title>{label}</title>{''.join(parts)}</svg>"
    )


def _measures(seg: Segment) -> list[float]:
    """Every interval a timing judge could have measured in one segment, in ms."""
    out = []
    if seg.reply:
        out.append((seg.reply[0].start - seg.command_end) * 1e3)
    for run in (seg.reply, seg.later):
        for a, b in pairwise(run):
            out += [(b.start - a.end) * 1e3, (b.start - a.start) * 1e3]
    return out


def _first_owners(each: Iterable[list[float]]) -> tuple[dict[float, int] | None, int]:
    """Each distinct value of ``each`` segment's intervals with the first segment holding
    it, and how many intervals there were; None for the values if one is a NaN. Read as
    the segments come, so nothing is kept per interval: the arrays of every interval and
    numpy's stable argsort of them, which this replaces, were the peak of an hour's passive
    judgement (16 bytes an interval kept and some 25 more while sorting: 9.3 MB above what
    was held at 30 minutes of a busy capture). A dict keeps a key's first spelling, so of
    the equal -0.0 and 0.0 the one met first stays, with its segment, as the stable sort
    kept the first of each run of equal values."""
    first: dict[float, int] = {}
    add = first.setdefault
    count = 0
    for i, ms in enumerate(each):
        count += len(ms)
        for m in ms:
            add(m, i)
    if any(m != m for m in first):
        return None, count
    return first, count


class MeasureIndex:
    """Every interval of a cut's segments (:func:`_measures`), sorted, with the segment it
    was measured in: a whole-run case asks for the segment nearest its worst value, and an
    hour's recording holds 10^5 segments, scanned whole for each timing case before."""

    def __init__(
        self,
        cut: Sequence[Segment] = (),
        *,
        measures: Iterable[list[float]] = (),
        every_interval: bool = False,
    ):
        """``measures``: each segment's intervals, given instead of ``cut`` (for tests);
        ``every_interval``: every interval kept, sorted, not each distinct value once (tests
        compare both ways)."""
        #: kept as arrays, 16 bytes an interval where lists of floats and ints took 40 and
        #: more: the index outlives the report that built it (an hour's capture: 535,000
        #: intervals, held through every later run of a passive judgement). Each distinct
        #: value is kept once, with its first segment (:func:`_first_owners`): :meth:`nearest`
        #: reads no other owner of an equal run. That was done only from 50,000 intervals
        #: where numpy was loaded (a gate left from when numpy's argsort made that order);
        #: a simulated run's 33,000 intervals are 27 distinct values, and sorting them all
        #: was 16-20 ms of the page's renderer (issue 22). With a NaN, every interval, sorted
        #: as the (value, segment) pairs were.
        self.values: array[float] = array("d")
        self.owners: array[int] = array("q")
        if not cut:
            measures = list(measures)  # read twice below, perhaps
        if not every_interval:
            first, _ = _first_owners(map(_measures, cut) if cut else measures)
            if first is not None:
                ordered = sorted(first)  # distinct: no two equal, so no order among equals
                self.values.extend(ordered)
                self.owners.extend(map(first.__getitem__, ordered))
                return
        values, owners = array("d"), array("q")
        for i, ms in enumerate(map(_measures, cut) if cut else measures):
            values.extend(ms)
            owners.extend(repeat(i, len(ms)))
        if any(m != m for m in values):  # a NaN: ordered as the (value, segment) pairs were
            pairs = sorted(zip(values, owners, strict=True))
            self.values.extend(m for m, _ in pairs)
            self.owners.extend(i for _, i in pairs)
            return
        # a stable sort by value keeps equal values in segment order, as sorting (value,
        # segment) pairs did, without a tuple per interval (10^4 of them in a simulated run)
        order = sorted(range(len(values)), key=values.__getitem__)
        self.values.extend(map(values.__getitem__, order))
        self.owners.extend(map(owners.__getitem__, order))

    def nearest(self, target: float) -> int | None:
        """The first segment (in recording order) holding an interval nearest ``target``:
        the one a scan of every segment's intervals in order would pick."""
        values = self.values
        if not values:
            return None
        at = bisect_left(values, target)
        distance = min(abs(values[i] - target) for i in (at - 1, at) if 0 <= i < len(values))
        # values equal to one another sort by segment, so a run of equal values offers its
        # first owner only: one step per distinct value that is equally near, not one per
        # interval (a simulated run's 10^4 character gaps are a few values: each timing
        # case's look-up walked thousands of equal ones). Distinct values may be equally
        # near (a difference rounds), so the walk goes on while the distance holds.
        owners = self.owners
        near: list[int] = []
        i = at - 1  # equally near, below
        while i >= 0 and abs(values[i] - target) == distance:
            i = bisect_left(values, values[i], 0, i)  # the first of its equal run
            near.append(owners[i])
            i -= 1
        i = at  # equally near, above: the first of each equal run
        while i < len(values) and abs(values[i] - target) == distance:
            near.append(owners[i])
            i = bisect_right(values, values[i], i)
        return min(near)


def exchange_behind(
    findings: Sequence[Finding], events: Sequence[Event] | Transcript
) -> tuple[str, list[Event]] | None:
    """The exchange of the run behind a whole-run case's worst timing finding.

    Whole-run cases judge every reply of the transcript and attach no evidence; their finding
    keeps the worst measured value. The segment holding an interval equal to that value (the
    first, if several do) is the one a reader needs to see drawn. Given the run's
    :class:`Transcript`, the cut the whole-run cases judged is reused.
    """
    timed = [f for f in findings if f.measured_ms is not None]
    if not timed or not len(events):
        return None
    target = max(timed, key=lambda f: f.verdict.rank)
    if isinstance(events, Transcript):
        cut = whole_cut(events)
        if isinstance(cut, LazyCut):  # a passive judgement's: the index kept, no segment
            index = memo(
                events, "_whole_measure_index", len(events.events), lambda: MeasureIndex(cut)
            )
        else:
            index = cut.derived("measure_index", None, lambda: MeasureIndex(cut))
    else:
        cut = segments(events)
        index = MeasureIndex(cut)
    found = index.nearest(target.measured_ms)
    if found is None:
        return None
    best = cut[found]
    drawn = [best.break_event] if best.break_event else []
    drawn += best.command + best.reply + best.later[:80]
    label = (
        f"{escape_wire(best.text)}, the exchange behind {target.requirement}'s "
        f"{target.measured_ms:.2f} ms ({target.verdict}; the run's other replies are in "
        "transcript.jsonl)"
    )
    return label, sorted(drawn, key=lambda e: e.start)
