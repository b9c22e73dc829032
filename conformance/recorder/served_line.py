"""The played sensors served in real time, for a recorder that is outside the virtual bus.

``--port rfc2217-serve://127.0.0.1:0`` (``0``: the OS picks a free port) makes the tool an
RFC 2217 server: one emulated line
(:class:`~conformance.emulator_server.realtime.RealTimeLine`) with
a :class:`PlayedBus` on it, which puts every played sensor of the current scenario on that
line, as the sim bus does. The recorder under test connects as a client (``rfc2217://HOST:PORT``,
breaks through SET_CONTROL); the golden recorder does so through
:class:`~conformance.links.serial_link.SerialLink`, once per scenario as a logger woken by
its schedule would.

The judges read the line as the sensors see it, so the :class:`PlayedBus` keeps the transcript
in the sim bus's form: the recorder's breaks and characters with origin ``tool``, each sensor's
characters under its own name, all stamped on the served line's clock with its declared
uncertainty (what the network between recorder and line, and the scheduling of both ends, may
add to a stamp). How well the line kept its own schedule is noted after every scenario.
"""

from __future__ import annotations

import bisect
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from math import inf
from urllib.parse import parse_qs, urlsplit

from ..emulator_server.realtime import RealTimeLine
from ..emulator_server.servers import TcpEmulatorServer
from ..links.base import BusEnd, LinkInfo
from ..links.factory import LOCAL_NET_UNCERTAINTY, REMOTE_NET_UNCERTAINTY, _is_loopback
from ..links.host_stall import note_text as stall_note
from ..links.priority import quick_gil_handover
from ..ports import PortError
from ..sim.bus import BusDevice, Frame, earliest_frame
from ..transcript import TOOL, Event, EventKind, Transcript

SCHEME = "rfc2217-serve"
#: Keys of the port's query string (as on ``sim://``): a golden-recorder fault, or a recorder
#: program ``package.module:callable`` run in this process over the served line.
RECORDER_KEYS = ("recorder-faults", "recorder")
#: Marking after the recorder finished that counts as a quiet line: every played sensor has
#: gone to standby (100 ms) and has nothing left to send.
QUIET = 0.25
#: Poll period of the settle wait.
SETTLE_POLL = 0.02


def is_served(port: str) -> bool:
    return port.startswith(f"{SCHEME}://")


@dataclass
class ServeSpec:
    """Where to serve the played sensors, and the query's recorder options."""

    host: str
    port: int
    extra: dict[str, str] = field(default_factory=dict)


def parse_served(port: str) -> ServeSpec:
    """``rfc2217-serve://HOST:PORT?recorder-faults=no-retries`` -> :class:`ServeSpec`."""
    parts = urlsplit(port)
    try:
        number = parts.port
    except ValueError as exc:
        raise PortError(f"port {port!r}: {exc}") from exc
    if not parts.hostname or number is None:
        raise PortError(f"port {port!r}: write {SCHEME}://HOST:PORT (PORT 0: any free port)")
    params = {k: v[-1] for k, v in parse_qs(parts.query, keep_blank_values=True).items()}
    extra = {k: params.pop(k) for k in RECORDER_KEYS if k in params}
    if params:
        known = ", ".join(RECORDER_KEYS)
        raise PortError(f"unknown {SCHEME} parameters {sorted(params)} (known: {known})")
    return ServeSpec(parts.hostname, number, extra)


class PlayedBus:
    """The played sensors as one device of a real-time line, and the line's transcript.

    The line calls the device methods from its own thread; :meth:`set_devices` and the
    readers come from the session's thread, so a lock guards the device list and the
    transcript. Events are kept in order of their start: a recorder character is heard when
    its stop bit ends, after a sensor character that may have started during it.
    """

    name = "played-bus"

    def __init__(self, uncertainty: float, clock: Callable[[], float]) -> None:
        self.uncertainty = uncertainty
        self._clock = clock
        self.devices: list[BusDevice] = []
        self.transcript = Transcript()
        self._lock = threading.RLock()
        self._busy = -inf  # end of the last sensor character: the next cannot start before
        self.last_end = -inf  # end of the last event on the line, whoever sent it

    def set_devices(self, devices: Sequence[BusDevice]) -> None:
        with self._lock:
            self.devices = list(devices)

    def add(self, event: Event) -> int:
        """Insert ``event`` in start order; its index in the transcript."""
        with self._lock:
            events = self.transcript.events
            at = bisect.bisect_right(events, event.start, key=lambda e: e.start)
            events.insert(at, event)
            if event.kind is not EventKind.NOTE:
                self.last_end = max(self.last_end, event.end)
            return at

    def pending(self) -> bool:
        """Whether a played sensor still plans to transmit (a late reply, a service request)."""
        with self._lock:
            return any(d.next_frame() is not None for d in self.devices)

    # -- BusDevice (the line's thread) --------------------------------------------------------
    def on_break(self, start: float, end: float) -> None:
        self.on_break_within(start, end, 0.0)

    def on_break_within(self, start: float, end: float, room: float) -> None:
        """A recorder break; ``room`` > 0: the served line could place its ends only within
        that many s (events read together), so where it ended, and so its length and the
        marking after it, are known only to the stamps' uncertainty plus the room
        (``duration_uncertainty``, which the break judges weigh)."""
        doubt = self.uncertainty + room if room > 0 else None
        event = Event(
            EventKind.BREAK,
            TOOL,
            start,
            end,
            uncertainty=self.uncertainty,
            duration_uncertainty=doubt,
        )
        with self._lock:
            self.add(event)
            for device in self.devices:
                device.on_break(start, end)

    def on_char(self, wire: int, start: float, end: float) -> None:
        self.on_char_within(wire, start, end, 0.0)

    def on_char_within(self, wire: int, start: float, end: float, doubt: float) -> None:
        """A recorder character; ``doubt`` > 0: the served line read it together with others
        and may have laid it that many s from where it was sent (the kernel merges packets
        nobody read yet), so its stamp carries the stamps' uncertainty plus that doubt, and
        the judges that time it (R-7.0-06/-13/-17, R-7.1-01, R-7.2-02) weigh it."""
        u = self.uncertainty + doubt if doubt > 0 else self.uncertainty
        with self._lock:
            event = Event(EventKind.CHAR, TOOL, start, end, wire=wire, uncertainty=u)
            self.add(event)
            for device in self.devices:
                device.on_char(wire, start, end)

    def _next(self) -> tuple[BusDevice, Frame] | None:
        return earliest_frame(self.devices)

    def next_frame(self) -> Frame | None:
        with self._lock:
            nxt = self._next()
            return nxt[1] if nxt is not None else None

    def pop_frame(self) -> Frame:
        """Commit the earliest sensor character; the other sensors hear it (as on the sim bus,
        a sensor that starts while another transmits is queued behind it).

        The line delivers a character at its planned end, or at once when it commits it later
        than that (a machine too busy to keep real time); the stamp says when it really left,
        so a stall shows in the transcript as the pause the recorder saw, not as on-time."""
        with self._lock:
            nxt = self._next()
            if nxt is None:
                raise RuntimeError("no played sensor has a character to send")
            device, frame = nxt
            device.pop_frame()
            start = max(frame.start, self._busy, self._clock() - frame.duration)
            end = start + frame.duration
            self._busy = end
            self.add(
                Event(
                    EventKind.CHAR,
                    device.name,
                    start,
                    end,
                    wire=frame.wire,
                    uncertainty=self.uncertainty,
                )
            )
            for other in self.devices:
                if other is not device:
                    other.on_char(frame.wire, start, end)
            return Frame(start, frame.wire, frame.duration)


class ServedLine(BusEnd):
    """The tool's end of the served line: what the run's reports read as its link (kind,
    breaks, uncertainty, transcript, clock). The tool transmits nothing on it itself: the
    played sensors do, on the line's thread."""

    def __init__(self, spec: ServeSpec, widen_to: float | None = None) -> None:
        host = spec.host
        loopback = _is_loopback(f"x://{host}:0")
        uncertainty = LOCAL_NET_UNCERTAINTY if loopback else REMOTE_NET_UNCERTAINTY
        # the user's figure widens the network's, as on every link (never narrows it); the
        # played sensors' stamps carry it, so a replay of the run reads the same figure
        uncertainty = max(uncertainty, widen_to or 0.0)
        self.info = LinkInfo(kind=SCHEME, can_break=True, timing_uncertainty=uncertainty)
        self._t0 = time.perf_counter()
        self.bus = PlayedBus(uncertainty, self.now)
        self.line = RealTimeLine(
            self.bus, lambda _data: None, clock=self.now, on_stall=self._stalled
        )
        self.log: list[str] = []
        try:
            self.server = TcpEmulatorServer(self.line, host, spec.port, log=self.log.append)
        except OSError as exc:
            raise PortError(f"cannot serve on {host}:{spec.port}: {exc}") from exc
        # the line's thread must get the interpreter back at once when a frame is due, also
        # while the golden recorder is between scenarios and this process judges or reports
        self._switch_interval = quick_gil_handover()
        self.line.start()
        self._thread = threading.Thread(target=self.server.serve, name="sdi12-served", daemon=True)
        self._thread.start()
        self._closed = False

    @property
    def transcript(self) -> Transcript:
        return self.bus.transcript

    @property
    def url(self) -> str:
        """Where a recorder connects (``rfc2217://HOST:PORT`` with the port actually bound)."""
        return self.server.url

    def now(self) -> float:
        """The line's clock: seconds since the server started."""
        return time.perf_counter() - self._t0

    def note(self, text: str) -> None:
        self.bus.add(Event(EventKind.NOTE, TOOL, self.now(), self.now(), text=text))

    def _stalled(self, stall: float) -> None:
        """The line's thread came back ``stall`` s late: this process was held up, the played
        sensors with it (and an in-process recorder). Noted as the serial link notes its
        reader's (:mod:`~conformance.links.host_stall`), so the recorder judges read what it
        held up as the tool's host's doing, not the recorder's (truth32)."""
        self.note(stall_note(stall))

    def settle(self, longest: float) -> None:
        """Wait (at most ``longest`` s) until the line has been quiet for :data:`QUIET` and no
        played sensor plans to transmit, so late sensor output stays with its scenario."""
        deadline = time.monotonic() + longest
        while time.monotonic() < deadline:
            quiet = self.now() - max(self.bus.last_end, 0.0) >= QUIET
            if quiet and not self.bus.pending():
                return
            time.sleep(SETTLE_POLL)

    def errors(self) -> list[BaseException]:
        return list(self.line.errors)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self.server.stop()
        self._thread.join(timeout=2.0)
        self.line.stop()
        sys.setswitchinterval(self._switch_interval)
