"""A bare bus device for the sim bus's tests: what it sends is a
:class:`~conformance.emulator.transmitter.Transmitter`'s queue, offered frame by frame
(``BusDevice``) and as runs (``PlansFrames``), with nothing of a sensor's state around it.
Subclasses plan its replies (in ``__init__`` or when they hear a character)."""

from __future__ import annotations

from conformance.emulator.transmitter import Transmitter


class TransmitterDevice:
    """A device that sends what its :attr:`tx` holds and hears nothing unless told to."""

    name = "dut"

    def __init__(self) -> None:
        self.tx = Transmitter()

    def on_break(self, start: float, end: float) -> None:
        pass

    def on_char(self, wire: int, start: float, end: float) -> None:
        pass

    def next_frame(self):  # noqa: ANN201 - as BusDevice
        return self.tx.next_frame()

    def pop_frame(self):  # noqa: ANN201 - as BusDevice
        return self.tx.pop_frame()[0]

    def frames_ahead(self):  # noqa: ANN201 - as PlansFrames
        return self.tx.ahead()

    def pop_frames(self, count: int) -> None:
        self.tx.pop_frames(count)
