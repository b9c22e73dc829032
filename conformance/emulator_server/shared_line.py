"""Several sensors on one served line (``emulate --sensors 0,1:FAULT,3``): a bus of emulators
that the real-time line drives as one device.

:class:`~conformance.emulator_server.realtime.RealTimeLine` schedules one
:class:`~conformance.sim.bus.BusDevice`: it hands it the recorder's breaks and characters and
commits the frames it offers when their start comes. :class:`SharedLine` is that device for a
bus: it hands every break and recorder character to each sensor, offers the earliest frame of
any of them, and when the line commits it, the other sensors hear it, so their replies meet on
the wire as on a real multi-drop line (a sensor with the ``answers-foreign-reply`` fault hears
its neighbour's reply and answers it).

Frames are arbitrated as :class:`~conformance.sim.bus.SimBus` does it: a sensor that would
start while another's character is still on the wire is queued behind it (its frame is offered
at the end of the one before). Two sensors at one address therefore interleave their replies
(``00<CR><CR><LF><LF>``), which the run's discovery calls a duplicate address; no bit-level
collision is modelled. Every call comes from the line's thread, as for a single device.
"""

from __future__ import annotations

from collections.abc import Sequence
from math import inf

from ..sim.bus import BusDevice, Frame, earliest_frame


class SharedLine:
    """The sensors of one served line, as the single device the real-time line drives."""

    name = "shared-line"

    def __init__(self, devices: Sequence[BusDevice]) -> None:
        if len(devices) < 2:
            raise ValueError("a shared line carries at least two sensors")
        self.devices = list(devices)
        self._busy = -inf  # end of the last sensor character: the next cannot start before

    def on_break(self, start: float, end: float) -> None:
        for device in self.devices:
            device.on_break(start, end)

    def on_char(self, wire: int, start: float, end: float) -> None:
        """A recorder character: every sensor hears it."""
        for device in self.devices:
            device.on_char(wire, start, end)

    def next_frame(self) -> Frame | None:
        """The earliest character any sensor plans, no earlier than the wire is free: the line
        waits for that time, so a queued character leaves (and reaches the recorder) one frame
        after the one before it, not on top of it."""
        nxt = earliest_frame(self.devices)
        if nxt is None:
            return None
        frame = nxt[1]
        if frame.start >= self._busy:
            return frame
        return Frame(self._busy, frame.wire, frame.duration)

    def pop_frame(self) -> Frame:
        """Commit the earliest character; the other sensors hear it (stamped where it goes on
        the wire), as on the simulated bus."""
        nxt = earliest_frame(self.devices)
        if nxt is None:
            raise RuntimeError("no sensor on the shared line has a character to send")
        device, planned = nxt
        device.pop_frame()
        start = max(planned.start, self._busy)
        end = start + planned.duration
        self._busy = end
        for other in self.devices:
            if other is not device:
                other.on_char(planned.wire, start, end)
        return Frame(start, planned.wire, planned.duration)


__all__ = ["SharedLine"]
