"""What a link is: moves breaks and characters, stamps them, and declares what it can do.

Every link records into one :class:`~conformance.transcript.Transcript`. The tool side
(master engine in the sensor role, played sensors in the recorder role) only ever talks to a
:class:`Link`; nothing above this layer knows whether the bus is simulated or real.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

from ..protocol.timing import CHAR_TIME
from ..transcript import Event, EventKind, Transcript


@dataclass(frozen=True)
class LinkInfo:
    """Capabilities of a link; cases that need what a link lacks become INCONCLUSIVE/N/A."""

    kind: str  # "sim", "serial", "rfc2217", "socket", "adapter"
    can_break: bool = True
    passes_unsolicited: bool = True  # service requests and raw HB packets reach us
    binary: bool = True  # 8N1 bytes with no CR LF framing are passed
    timing_uncertainty: float = 0.0  # seconds, on every event stamp
    virtual_time: bool = False
    #: The DUT's characters come with its own bit timing (baud rate). False on a harness link
    #: (``exec:``/``unix:``), where the DUT names bytes and the tool makes the frames.
    bit_timing: bool = True


#: Why R-4.1-01 (the bit rate) stays INCONCLUSIVE on a link without ``bit_timing``.
NO_BIT_TIMING = (
    "this link carries bytes and the tool makes their 1200-baud frames (a harness: the DUT's "
    "UART setting is not part of it), so the bit rate is not observed"
)


class LinkError(RuntimeError):
    """The link itself failed (port vanished, permission denied...): an ERROR, not a FAIL."""


StopCondition = Callable[[list[Event]], bool]


class Link(ABC):
    """The tool's end of the bus.

    Times are seconds on the link's own clock (:meth:`now`). ``receive`` is always bounded by a
    deadline, so a silent or babbling device can never hang the tool.
    """

    info: LinkInfo
    transcript: Transcript

    @abstractmethod
    def now(self) -> float: ...

    @abstractmethod
    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        """Hold spacing for ``duration`` s; return the break as achieved.

        ``exact``: the length matters near a threshold (timing cases); a real link then
        times it with the UART's bit clock where it can (a NUL at a lower bit rate), and
        otherwise as well as the host can. Ordinary wake-up breaks leave it False."""

    @abstractmethod
    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        """Send frames (``wire`` holds the 8 bits of each); ``gap`` s of marking between them.

        Returns once the last stop bit is on the wire.
        """

    @abstractmethod
    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        """Characters from the DUT, oldest first, until ``until(chars)`` is true, the clock
        reaches ``deadline``, or (once a character has arrived) the line has marked for
        ``idle`` s after the last stop bit. Characters not returned stay for the next call."""

    def wait(self, duration: float) -> None:
        """Keep the line marking (not driving) for ``duration`` s; arrivals are queued."""
        self.wait_until(self.now() + duration)

    @abstractmethod
    def wait_until(self, time: float) -> None: ...

    def close(self) -> None:  # noqa: B027 - optional for links without resources
        """Release the port."""

    # helpers shared by all links
    def last_activity(self) -> float:
        """End of the most recent break or character on the wire (either side)."""
        for event in reversed(self.transcript.events):
            if event.kind is not EventKind.NOTE:
                return event.end
        return float("-inf")

    def char_time(self) -> float:
        return CHAR_TIME
