"""What a passive judging is asked to do: kept apart from :mod:`.passive` (which runs it)
so that ``judge``'s planning can build one without importing the run."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PassiveJob:
    """What to judge passively and how (:func:`conformance.offline.judge.passive_job` fills
    it from ``judge``'s options)."""

    recording: str
    format: str  # one of FORMATS
    role: str = "both"  # sensor, recorder or both
    address: str | None = None
    channel: str | None = None
    tx_channel: str | None = None
    sdi_version: str | None = None
    report_dir: str | None = None
    invert: bool | None = None  # None: detected
    baud: int = 1200
    strict: bool = False
    glitch_filter_us: float | None = None  # None: the decoder's default (1/16 bit)
    force: bool = False  # judge a capture whose decode looks wrong
