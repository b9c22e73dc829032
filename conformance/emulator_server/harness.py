"""``emulate --harness exec:PROGRAM``: outside sensor firmware served in real time.

``--port exec:`` runs a sensor harness on the tool's virtual clock: exact stamps, no echo, no
USB batching. Served here, the same harness becomes the device of the
:class:`~conformance.emulator_server.realtime.RealTimeLine`, so a recorder (this tool with
``--port rfc2217://...``) reaches it through the bench models (``--echo``, ``--usb-latency``,
``--jitter``) and a loaded machine, as firmware on a bench is reached. The line's clock is the
wall clock (monotonic, from the server's start): each recorder character is told to the
harness when its stop bit ends, each ``tx START`` it plans is committed when START comes, and a
``wait T`` is answered with ``time T`` when the clock gets there with nothing on the line
first. The harness protocol is :class:`~conformance.harness.device.HarnessDevice`'s, unchanged.
"""

from __future__ import annotations

import time

from ..harness import protocol as proto
from ..harness.channel import ChildChannel, HarnessError
from ..harness.device import HarnessDevice, is_harness_port, open_channel
from ..links.priority import SERVED_FIRMWARE, realtime_priority
from ..ports import PortError
from ..sim.bus import BreakFrame, Frame


class LineClock:
    """The served line's clock, read as :class:`HarnessDevice` reads the bus's (``.now``)."""

    def __init__(self, start: float | None = None) -> None:
        self.start = time.perf_counter() if start is None else start

    def __call__(self) -> float:
        """Seconds since the server started: the harness's times begin near 0, as on exec:."""
        return time.perf_counter() - self.start

    @property
    def now(self) -> float:
        return self()


class ServedHarness(HarnessDevice):
    """A sensor harness as the real-time line's device. A failure (protocol error, crash,
    hang) raises :class:`HarnessError` on the line's thread, which stops the line and, through
    its ``on_failure``, the server."""

    #: the harness's process got a real-time scheduling class (``exec:`` only; a ``unix:``
    #: harness is someone else's process)
    realtime_priority = False

    def pop_frame(self) -> Frame:
        """Commit the planned character; a planned sensor break is refused: the line sends a
        device's frames as bytes (a break would go out as a NUL character), as ``emulate``
        refuses the reference sensor's ``break-before-reply``."""
        if isinstance(self.next_frame(), BreakFrame):
            raise self.channel.fail(
                "planned a break (brk): a sensor's own break is not served on a real-time "
                "line; run it with --port exec:"
            )
        return super().pop_frame()

    def close(self) -> None:
        """End the harness (``bye``), as the run's link does when it closes."""
        self.channel.close(proto.BYE)


def open_served_harness(port: str, clock: LineClock) -> ServedHarness:
    """Start (``exec:``) or connect to (``unix:``) the sensor harness ``port`` and greet it;
    :class:`PortError` with the harness's own words if it cannot be."""
    if not is_harness_port(port):
        raise PortError(f"--harness wants exec:PROGRAM [ARGS] or unix:PATH, not {port!r}")
    try:
        channel = open_channel(port)
    except HarnessError as exc:
        raise PortError(str(exc)) from exc
    # the firmware's answers are on the line's critical path: on a loaded machine an ordinary
    # process answered a 1 kHz tick's wake-ups late and the uOS++ sensor's reply began 31.44
    # ms after the command beside two CPU burners (bench31), a FAIL of R-7.0-10 that was the
    # serving machine's, not the firmware's
    fast = isinstance(channel, ChildChannel) and realtime_priority(
        SERVED_FIRMWARE, channel.proc.pid
    )
    try:
        device = ServedHarness(channel, clock, name=port)  # type: ignore[arg-type]
    except HarnessError as exc:
        channel.close()
        raise PortError(str(exc)) from exc
    device.realtime_priority = fast
    return device
