"""Run a sans-I/O bus device (the reference sensor emulator) against the wall clock.

The emulator never reads a clock: it hears stamped breaks and characters and offers frames
with start times (:class:`~conformance.sim.bus.BusDevice`). On the sim bus a virtual clock
jumps from event to event; here one thread plays the same role in real time. It keeps the
emulated wire: the recorder's bytes arrive (from a socket or a UART) and are laid on it back
to back at 1200 baud; each is handed to the device when its stop bit ends, a break when its
spacing ends; each frame the device offers is committed when its start time comes and
delivered at ``deliver`` (its end for a network peer, which sees a byte after its stop bit;
its start for a UART, which shifts the byte out itself).

Transports call :meth:`RealTimeLine.tool_bytes` / :meth:`break_on` / :meth:`break_off` from
their own threads; every device call happens on the line's thread.
"""

from __future__ import annotations

import contextlib
import heapq
import itertools
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from math import inf

from ..protocol.timing import CHAR_TIME
from ..sim.bus import BusDevice

SPIN = 0.0008  # s: poll the last stretch before a due time instead of oversleeping it
LATE_NOTICE = 2e-3  # s: a frame committed later than this behind plan is counted as late
MAX_IDLE_WAIT = 0.05  # s: the thread re-checks its stop flag at least this often


@dataclass(order=True)
class _Due:
    """Something the line must do at ``time``; ``seq`` keeps equal times in arrival order."""

    time: float
    seq: int
    action: Callable[[], None] = field(compare=False)


class RealTimeLine:
    """One emulated SDI-12 line: a device on it, a recorder at the other end of ``send``."""

    def __init__(
        self,
        device: BusDevice,
        send: Callable[[bytes], None],
        *,
        deliver_at_end: bool = True,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.device = device
        self._send = send
        self._deliver_at_end = deliver_at_end
        self._clock = clock
        self._cond = threading.Condition()
        self._due: list[_Due] = []
        self._seq = itertools.count()
        self._tool_free = -inf  # end of the recorder's last frame on the emulated wire
        self._break_start: float | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="sdi12-emulated-line", daemon=True)
        self.frames_sent = 0
        self.errors: list[BaseException] = []
        # how far behind its own schedule the line committed device frames: on a machine too
        # busy to keep real time the emulated sensor's timing is not what it planned
        self.worst_lateness = 0.0
        self.late_frames = 0  # committed more than LATE_NOTICE after their planned start

    def now(self) -> float:
        return self._clock()

    # -- transport side (any thread) -----------------------------------------------------------
    def set_sender(self, send: Callable[[bytes], None]) -> None:
        """Point the device's output at a new peer (a new client connection)."""
        with self._cond:
            self._send = send

    def tool_bytes(self, data: bytes, at: float | None = None) -> None:
        """Recorder bytes that reached the line at ``at``: each takes one frame, back to
        back behind the previous one; bytes sent while the recorder holds a break are lost."""
        at = self.now() if at is None else at
        with self._cond:
            if self._break_start is not None:
                return
            for wire in data:
                start = max(at, self._tool_free)
                end = start + CHAR_TIME
                self._tool_free = end
                self._push(end, lambda w=wire, s=start, e=end: self.device.on_char(w, s, e))
            self._cond.notify()

    def break_on(self, at: float | None = None) -> None:
        at = self.now() if at is None else at
        with self._cond:
            if self._break_start is None:
                self._break_start = max(at, self._tool_free)

    def break_off(self, at: float | None = None) -> None:
        at = self.now() if at is None else at
        with self._cond:
            start, self._break_start = self._break_start, None
            if start is None:
                return
            end = max(at, start)
            self._tool_free = end
            self._push(end, lambda s=start, e=end: self.device.on_break(s, e))
            self._cond.notify()

    def timekeeping(self) -> str:
        """One line for the server log: how well the line kept its schedule so far."""
        return (
            f"line kept real time within {self.worst_lateness * 1e3:.1f} ms "
            f"({self.late_frames} of {self.frames_sent} frames more than "
            f"{LATE_NOTICE * 1e3:.0f} ms late)"
        )

    def start(self) -> RealTimeLine:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        with self._cond:
            self._cond.notify()
        if self._thread.is_alive():
            self._thread.join(timeout=1.0)

    # -- the line's thread ---------------------------------------------------------------------
    def _push(self, when: float, action: Callable[[], None]) -> None:
        heapq.heappush(self._due, _Due(when, next(self._seq), action))

    def _run(self) -> None:
        while not self._stop.is_set():
            with self._cond:
                nxt = self._next_due()
                now = self.now()
                if nxt > now + SPIN:
                    self._cond.wait(min(nxt - now - SPIN, MAX_IDLE_WAIT))
                    continue
            while self.now() < nxt:
                time.sleep(0)
            self._step()

    def _next_due(self) -> float:
        """When the line next has something to do (device frame start or a queued action)."""
        frame = self.device.next_frame()
        nxt = frame.start if frame is not None else inf
        if self._due:
            nxt = min(nxt, self._due[0].time)
        return nxt

    def _step(self) -> None:
        """Do the earliest due thing: deliver a recorder event, or commit a device frame."""
        with self._cond:
            frame = self.device.next_frame()
            queued = self._due[0] if self._due else None
            try:
                if queued is not None and (frame is None or queued.time <= frame.start):
                    if queued.time > self.now():
                        return
                    heapq.heappop(self._due)
                    queued.action()
                    return
                if frame is None or frame.start > self.now():
                    return
                self.device.pop_frame()
                lateness = self.now() - frame.start
                self.worst_lateness = max(self.worst_lateness, lateness)
                self.late_frames += lateness > LATE_NOTICE
                deliver = frame.start + (frame.duration if self._deliver_at_end else 0.0)
                self._push(deliver, lambda w=frame.wire: self._emit(w))
            except Exception as exc:  # a device bug must not kill the line silently
                self.errors.append(exc)
                raise

    def _emit(self, wire: int) -> None:
        self.frames_sent += 1
        with contextlib.suppress(OSError):  # the peer left; the device runs on for the next
            self._send(bytes([wire]))
