"""The notes an export keeps in a capture (a .sr member, a VCD ``$comment``).

``sdi12-conform export`` keeps the run's NOTE events there: the options the run was made with
and, in the recorder role, where each scenario began and what the recorder said of it. Judging
the exported capture can then repeat that run's cases against it. Captures from anywhere else
have none.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Sequence

from ..transcript import TOOL, Event, EventKind
from .formats import sniff
from .sigrok import ZIP_DAMAGE
from .writers import SR_COMMENT_MEMBER

PREFIX = "sdi12-conform-notes "
VCD_HEADER_LIMIT = 1 << 20  # characters read looking for the notes before giving up


def notes_comment(notes: Sequence[Event], t0: float) -> str | None:
    """One line holding ``notes`` with times on the capture's clock (``t0`` = its time 0)."""
    kept = [[e.start - t0, e.text] for e in notes if e.kind is EventKind.NOTE]
    return PREFIX + json.dumps(kept) if kept else None


def embedded_notes(path: str) -> list[Event]:
    """The NOTE events an export kept in the capture at ``path`` (empty when none)."""
    text = _comment(path)
    if not text or not text.startswith(PREFIX):
        return []
    try:
        rows = json.loads(text[len(PREFIX) :])
        return [Event(EventKind.NOTE, TOOL, float(t), float(t), text=str(n)) for t, n in rows]
    except (ValueError, TypeError):
        return []


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
            if text.startswith(PREFIX):
                return text
    return None
