"""What a link is: moves breaks and characters, stamps them, and declares what it can do.

Every link records into one :class:`~conformance.transcript.Transcript`. The tool side
(the tool recorder in the sensor role, played sensors in the recorder role) only ever talks to a
:class:`Link`; nothing above this layer knows whether the bus is simulated or real.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..protocol.timing import CHAR_TIME
from ..transcript import Event, EventKind, Transcript

#: a module constant (:meth:`Link.last_activity`): a member read off the enum goes through its
#: metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_NOTE = EventKind.NOTE

if TYPE_CHECKING:
    from ..results import CaseRecord
    from .echo import EchoTracker
    from .meter import TimingMeter


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
    #: Each character event lasts its own measured frame (ten of its sender's bits), so a
    #: frame's length is its bit rate: a version-2 harness (a firmware kit) says so.
    frame_lengths: bool = False


#: Why R-4.1-01 (the bit rate) stays INCONCLUSIVE on a link without ``bit_timing``.
NO_BIT_TIMING = (
    "this link carries bytes and the tool makes their 1200-baud frames (a harness: the DUT's "
    "UART setting is not part of it), so the bit rate is not observed"
)


class LinkError(RuntimeError):
    """The link itself failed (port vanished, permission denied...): an ERROR, not a FAIL."""


StopCondition = Callable[[list[Event]], bool]


class LineEnd:
    """A :data:`StopCondition`: stop once ``before`` and the characters received so far hold
    ``most`` characters or more, or end in CR LF (7-bit, parity ignored). The tool
    recorder's read of a one-line 7E1 reply on from ``before`` (``Framing.stop_after``).
    Kept as data as well as a call, so a link that makes the characters itself (the sim
    bus's run of a reply) checks it inline instead of calling it after every character."""

    __slots__ = ("before", "most")

    def __init__(self, before: list[Event], most: int) -> None:
        self.before = before
        self.most = most

    def __call__(self, got: list[Event]) -> bool:
        before = self.before
        if len(before) + len(got) >= self.most:
            return True
        last = got[-2] if len(got) > 1 else before[-1] if before else None
        return last is not None and last.wire & 0x7F == 0x0D and got[-1].wire & 0x7F == 0x0A


class BusEnd(ABC):
    """What a run holds of the bus: its record, what it can do, its clock, and the optional
    abilities a report asks every kind about (python-can's ``BusABC`` way: a default for each,
    overridden by the kinds that have it, instead of probing with ``getattr``).

    A :class:`Link` is a bus end the tool also transmits on; a line the tool serves to a
    recorder under test and a recording judged after the fact are bus ends that are not.
    """

    info: LinkInfo
    transcript: Transcript
    #: s: the user's --timing-uncertainty-ms, applied where the port is opened; it widens
    #: what the link declares or measures and never narrows it
    widened: float = 0.0
    #: the stamp statistics of a real interface (:mod:`~conformance.links.meter`); None for
    #: a bus end whose stamps are exact or fixed
    meter: TimingMeter | None = None
    #: what the interface echoes of the tool's own characters (:mod:`~conformance.links.echo`)
    echo: EchoTracker | None = None
    #: the DUT is a harness program the link runs (``exec:``/``unix:``): the reports keep
    #: :meth:`harness_stderr`, even when the harness has none to give
    runs_harness: bool = False
    #: a ``transcript.jsonl`` written of this bus end's events is kept as its reading (a run
    #: judged again at once, by replay or through its capture, reads it back); a loaded
    #: recording's is not (nothing reads a passive judgement's copy back, and an hour's
    #: capture kept it as a tuple of its 357,000 events through every later report set)
    keeps_written_reading: bool = True
    #: the reports read this bus end's events through :meth:`events_again` alone, never as
    #: the transcript's list (a recording judged passively, which does not grow: issue 22,
    #: a step towards a recording that is streamed from its file, not held)
    reads_again: bool = False

    @abstractmethod
    def now(self) -> float: ...

    def events_again(self) -> Iterator[Event]:
        """Every event of this bus end from its first, in recorded order, read afresh at each
        call: what a report reads the whole run through (the transcript file, the bus time,
        where the findings' evidence lies), so that a bus end whose record is a recording
        can give its events again as they come rather than hold them (issue 22). Here: the
        transcript's list, read in order."""
        return iter(self.transcript.events)

    def close(self) -> None:  # noqa: B027 - optional for bus ends without resources
        """Release the port."""

    def widen(self, uncertainty: float | None) -> None:
        """Take the user's timing uncertainty (s) as a floor under every stamp's."""
        if uncertainty is not None:
            self.widened = max(self.widened, uncertainty)

    def timing_uncertainty(self) -> float:
        """The uncertainty on every stamp now (s): the declared figure, or what a real link
        has measured of its own stamps so far, widened by the user's."""
        return max(self.info.timing_uncertainty, self.widened)

    def uncertainty_between(self, start: float, end: float) -> float:
        """The uncertainty of stamps between ``start`` and ``end``: more than
        :meth:`timing_uncertainty` only where a real link saw its own stamps irregular."""
        return self.timing_uncertainty()

    def describe(self) -> dict[str, object] | None:
        """The bench as measured (echo, how breaks are made, timing), for the reports; None
        for a bus end with no bench to describe."""
        return None

    def harness_stderr(self) -> str | None:
        """The tail of what a harness program wrote to stderr; None without a harness."""
        return None

    def reader_caught_up(self) -> None:  # noqa: B027 - only a link with a reader thread
        """Return once whatever this bus end has to note of its own host's stalls is in its
        transcript (:mod:`.host_stall`): a stimulus's records are marked from those notes."""

    def check_records(self, cases: list[CaseRecord]) -> None:  # noqa: B027 - optional
        """Vouch for the records before the verdicts are drawn (a harness, whose answers
        could have fallen out of step, checks them at the end); raises LinkError if not."""


class Link(BusEnd):
    """The tool's end of the bus, where it transmits.

    Times are seconds on the link's own clock (:meth:`now`). ``receive`` is always bounded by a
    deadline, so a silent or babbling device can never hang the tool.
    """

    #: This class's ``receive``, given ``idle`` and a :class:`LineEnd` whose ``before`` holds
    #: characters, counts the idle from the last of those until one of its own has come, so
    #: the rest of a one-line reply is one call (the tool recorder's read,
    #: :meth:`~conformance.tool_recorder.engine.ToolRecorder._listen`) instead of one a
    #: window of ``idle`` (issue 22: ~6 characters a call, 4.6 calls a reply). Read off the
    #: class, so a wrapper that forwards attributes to a link does not pass it on.
    reads_line_at_once: bool = False

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

    # helpers shared by all links
    def last_activity(self) -> float:
        """End of the most recent break or character on the wire (either side)."""
        for event in reversed(self.transcript.events):
            if event.kind is not _NOTE:
                return event.end
        return float("-inf")

    def received_by(self, end: float) -> float:
        """The latest the received character whose stamp ends at ``end`` can have ended on
        the wire: its stamp's end here. A real link whose stamps may be placed after the
        host already had the byte says less (:meth:`SerialLink.received_by`)."""
        return end

    def char_time(self) -> float:
        return CHAR_TIME
