"""A verdicts document without what differs between two runs of the same thing (wall-clock
stamps, the tool's own CPU, the manifest's hashes), so that two runs can be compared whole."""

from __future__ import annotations

#: what differs between two runs of the same thing: wall-clock stamps and the manifest's hashes
VOLATILE = frozenset(("started", "finished", "duration_s", "wall_s", "cpu_s", "manifest"))


def steady(data: object) -> object:
    """``data`` (a verdicts.json document, or its lines) without its :data:`VOLATILE` keys."""
    if isinstance(data, dict):
        return {k: steady(v) for k, v in data.items() if k not in VOLATILE}
    if isinstance(data, list):
        return [steady(v) for v in data]
    return data
