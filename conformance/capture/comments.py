"""What an export keeps in a capture about itself (a .sr member, a VCD ``$comment``, a CSV
comment line).

``sdi12-conform export`` keeps there the run's NOTE events (the options the run was made with
and, in the recorder role, where each scenario began and what the recorder said of it) and
which channel is the bus and which the tool's own TX. Judging the exported capture can then
repeat that run's cases against it with every character's sender known, with no option to
repeat (issue 19: a round trip that needed ``--tx-channel`` was judged passively by default).
Captures from anywhere else have none.

A CSV (Saleae's export format) has no place for metadata, so the export writes one comment
line after the header, led by ``;`` (the comment leader PulseView's CSV import skips); the
reader here skips such lines too.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field

from ..transcript import TOOL, Event, EventKind
from .formats import sniff
from .sigrok import ZIP_DAMAGE
from .writers import CSV_COMMENT_LEADER, SR_COMMENT_MEMBER

PREFIX = "sdi12-conform-notes "  # the notes alone (exports before the channels were kept)
CAPTURE_PREFIX = "sdi12-conform-capture "  # {"bus": ..., "tool": ..., "notes": [...]}
VCD_HEADER_LIMIT = 1 << 20  # characters read looking for the notes before giving up
CSV_HEADER_LINES = 4  # lines of a CSV read looking for the comment


@dataclass(frozen=True)
class CaptureMeta:
    """What an export said about its capture: the run's notes (capture clock), the channel
    carrying the bus and the one carrying only the tool's transmissions (None: not said)."""

    notes: list[Event] = field(default_factory=list)
    bus_channel: str | None = None
    tool_channel: str | None = None


def capture_comment(
    notes: Sequence[Event], t0: float, bus_channel: str, tool_channel: str | None
) -> str:
    """One line holding ``notes`` with times on the capture's clock (``t0`` = its time 0) and
    which channel is which."""
    kept = [[e.start - t0, e.text] for e in notes if e.kind is EventKind.NOTE]
    body = {"bus": bus_channel, "tool": tool_channel, "notes": kept}
    return CAPTURE_PREFIX + json.dumps(body)


def embedded_meta(path: str) -> CaptureMeta:
    """What the export kept in the capture at ``path`` (empty when it is not an export)."""
    text = _comment(path)
    try:
        if text and text.startswith(CAPTURE_PREFIX):
            body = json.loads(text[len(CAPTURE_PREFIX) :])
            bus, tool = body.get("bus"), body.get("tool")
            return CaptureMeta(
                _events(body.get("notes") or []),
                str(bus) if bus else None,
                str(tool) if tool else None,
            )
        if text and text.startswith(PREFIX):
            return CaptureMeta(_events(json.loads(text[len(PREFIX) :])))
    except (ValueError, TypeError, AttributeError):
        pass
    return CaptureMeta()


def embedded_notes(path: str) -> list[Event]:
    """The NOTE events an export kept in the capture at ``path`` (empty when none)."""
    return embedded_meta(path).notes


def _events(rows: list) -> list[Event]:
    return [Event(EventKind.NOTE, TOOL, float(t), float(t), text=str(n)) for t, n in rows]


def _comment(path: str) -> str | None:
    fmt = sniff(path)
    if fmt == "sr":
        try:
            with zipfile.ZipFile(path) as zf:
                if SR_COMMENT_MEMBER not in zf.namelist():
                    return None
                return zf.read(SR_COMMENT_MEMBER).decode("utf-8", errors="replace")
        except ZIP_DAMAGE:  # a damaged note member: the capture says nothing of its run
            return None
    if fmt == "vcd":
        with open(path, encoding="utf-8", errors="replace") as fh:
            header = fh.read(VCD_HEADER_LIMIT)
        for chunk in header.split("$enddefinitions", 1)[0].split("$comment")[1:]:
            text = chunk.split("$end", 1)[0].strip()
            if text.startswith((CAPTURE_PREFIX, PREFIX)):
                return text
    if fmt == "csv":
        with open(path, encoding="utf-8", errors="replace") as fh:
            for _ in range(CSV_HEADER_LINES):
                line = fh.readline().strip()
                if line.startswith(CSV_COMMENT_LEADER):
                    text = line[len(CSV_COMMENT_LEADER) :].strip()
                    if text.startswith(CAPTURE_PREFIX):
                        return text
    return None
