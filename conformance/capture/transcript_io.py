"""Reading a ``transcript.jsonl`` back (``Transcript.write_jsonl`` only writes one), so any
earlier run can be judged again or exported as a capture."""

from __future__ import annotations

import json

from ..transcript import Event, EventKind
from .errors import CaptureError


def event_from_json(obj: dict) -> Event:
    """The inverse of :meth:`Event.to_json`."""
    return Event(
        EventKind(obj["kind"]),
        str(obj["origin"]),
        float(obj["start"]),
        float(obj["end"]),
        wire=int(obj.get("wire", 0)),
        text=str(obj.get("text", "")),
        uncertainty=float(obj.get("uncertainty", 0.0)),
        duration_uncertainty=(
            None if obj.get("duration_uncertainty") is None else float(obj["duration_uncertainty"])
        ),
    )


def read_transcript_jsonl(path: str) -> list[Event]:
    """Every event of a transcript file, in file order; :class:`CaptureError` naming the line
    for anything that is not an event."""
    events: list[Event] = []
    try:
        with open(path, encoding="utf-8") as fh:
            for number, line in enumerate(fh, 1):
                if not line.strip():
                    continue
                try:
                    events.append(event_from_json(json.loads(line)))
                except (ValueError, KeyError, TypeError) as exc:
                    raise CaptureError(
                        path, f"line {number}: not a transcript event ({exc})"
                    ) from None
    except UnicodeDecodeError:
        raise CaptureError(path, "not text: binary data in a transcript") from None
    except OSError as exc:
        raise CaptureError(path, f"cannot read: {exc.strerror or exc}") from None
    return events
