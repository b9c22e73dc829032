"""A silent device for the sim bus, so that no device on it is taken for the DUT."""

from __future__ import annotations

from .bus import Frame


class LineMonitor:
    """A silent device on the sim bus. With it the bus names every sensor by its own name
    (``sensor0``...) even when one sensor plays alone, instead of calling it the DUT: in the
    recorder role the DUT is the recorder."""

    name = "monitor"

    def on_break(self, start: float, end: float) -> None:
        """Hears breaks; keeps nothing (the transcript has them)."""

    def on_char(self, wire: int, start: float, end: float) -> None:
        """Hears characters; keeps nothing."""

    def next_frame(self) -> Frame | None:
        return None

    def pop_frame(self) -> Frame:
        raise RuntimeError("the line monitor never transmits")
