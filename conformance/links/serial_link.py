"""A :class:`~conformance.links.base.Link` over any pyserial port or URL, in real time.

The port runs at 1200 baud 8N1; the even-parity bit of 7E1 characters is made and checked in
software (requirements.md implementation notes). A 7E1 frame and an 8N1 frame are both 10
bits, so commands go out as 7E1 and ``aDBn!`` packets come back as 8N1 on the same port
settings, and every received byte is kept whole in ``Event.wire``: a parity error is evidence
(``Event.parity_ok``), not something a UART silently drops.

A reader thread stamps each chunk of bytes as it arrives (with the kernel's receive stamps
where the port gives them, :mod:`~conformance.links.kernel_stamps`) and turns the stamps into
wire events (:mod:`~conformance.links.stamps`). On an interface that echoes the tool's own
characters the echoes are recognised (:mod:`~conformance.links.echo`) and become the tool's
events, stamped on the same receive path as the DUT's, so the path's latency cancels. What the
stamps are worth is measured as the run goes (:mod:`~conformance.links.meter`). Breaks and
short spacing pulses are timed by the UART's bit clock where the port can change its bit rate
(:mod:`~conformance.links.breaks`), and a transmit-enable line is raised for exactly the tool's
transmissions (:mod:`~conformance.links.driver_enable`). Every public call is bounded by its
deadline; a port that fails while the run goes on raises
:class:`~conformance.links.errors.PortVanished` from the next call.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections import deque

import serial

from ..protocol.timing import CHAR_TIME, RESPONSE_START_MAX, RESPONSE_START_MIN
from ..transcript import COLLISION, DUT, TOOL, Event, EventKind, Transcript
from .base import Link, LinkInfo, StopCondition
from .breaks import BaudPulse, BreakMaker, PulseRefused
from .driver_enable import Direction, TimedRelease
from .echo import EchoMode, EchoTracker, Expected, Heard
from .errors import BreakUnsupported, PortVanished
from .host_stall import STALL_MIN
from .host_stall import note_text as stall_note
from .meter import ECHO_FLOOR, TimingMeter
from .priority import READER, quick_gil_handover, realtime_priority
from .stamps import chunk_frames, overlap

READ_POLL = 0.02  # s: the reader thread's read timeout, so it notices close() promptly
SPIN = 0.0008  # s: the last stretch of a timed wait is polled, not slept (sleep overshoots)
ECHO_WAIT = 0.5  # s: beyond the latency bound, how long a known echo may take to come back
ECHO_WAIT_AUTO = 0.1  # s: the same while auto has not decided (a silent DUT costs it once)
BURST_MARGIN = 0.5e-3  # s: arrivals this much closer than latency jitter explains are a burst
RELEASE_MARGIN = 0.2e-3  # s: after the last stop bit before the driver is released
RELEASE_WAIT = 0.5  # s: longest wait for the timer thread's release
#: s: the longest a stimulus waits for an overdue reader thread to note a stall (it resumes with
#: the rest of the process; a reader still not back after this is not held up by a stall)
CATCH_UP = 0.25
TURNAROUND_LIMIT = RESPONSE_START_MIN / 2  # s: a later release may swallow a reply's start


def precise_sleep_until(clock_now, target: float) -> None:
    """Sleep until ``clock_now() >= target``: a coarse sleep, then short yields."""
    while True:
        left = target - clock_now()
        if left <= 0:
            return
        time.sleep(left - SPIN if left > 2 * SPIN else 0)


#: pushed frames whose arrival :meth:`SerialLink.received_by` keeps (the last reply's, with room)
PUSHED_KEPT = 64


class SerialLink(Link):
    """The tool's end of a real bus reached through ``port`` (an open pyserial port)."""

    def __init__(
        self,
        port: serial.SerialBase,
        info: LinkInfo,
        breaker: BreakMaker | None,
        *,
        name: str = "",
        echo: EchoMode = EchoMode.OFF,
        pulse: BaudPulse | None = None,
        direction: Direction | None = None,
    ) -> None:
        self.port = port
        self.info = info
        self.name = name or str(port.port)
        self.transcript = Transcript()
        self._breaker = breaker
        self._pulse = pulse
        self._direction = direction
        self._release = TimedRelease(direction, self.now) if direction is not None else None
        self._t0 = time.perf_counter_ns()
        self._cond = threading.Condition()
        self._rx: deque[Event] = deque()  # DUT characters not yet returned by receive()
        self._echoed: list[Event] = []  # the tool's echoed characters, not yet claimed
        self._state_echoes: list[float] = []  # arrival of echoed breaks and pulses
        # the tool's characters as written, kept out of the transcript while it is not yet
        # known whether their echo will stand for them (the first transmission on auto)
        self._planned_pending: list[Event] = []
        self._rx_floor = 0.0  # end of the last received frame: the next cannot start before
        # (floor before it, marking its stamps showed before it, arrival) of the last chunk
        self._previous_chunk = (0.0, 0.0, float("-inf"))
        self._last_origin = ""  # who sent the last frame recorded ("tool": its echo)
        # stamp end -> arrival of the last few frames the no-overlap rule placed after their
        # arrival (received_by): only those, and only the latest, are ever asked about
        self._pushed: dict[float, float] = {}
        self._widest_chunk = 1  # the most bytes seen under one arrival stamp (read_grace)
        self._tx_free = 0.0  # end of the tool's last frame on the wire
        self._failure: BaseException | None = None
        self._closing = threading.Event()
        self.realtime_priority = False  # the reader thread got a real-time class
        tape = getattr(port, "kernel_stamps", None)
        self._tape = tape
        self.meter = TimingMeter(info.timing_uncertainty, kernel_stamps=tape is not None)
        self.echo = EchoTracker(echo)
        self.meter.echo = self.echo.echoes
        self._switch_interval = quick_gil_handover()
        #: when the reader thread last finished a turn (perf_counter ns), its stall noted
        self._reader_back = time.perf_counter_ns()
        self._reader = threading.Thread(target=self._read_loop, name=f"sdi12-rx {self.name}")
        self._reader.daemon = True
        self._reader.start()

    # -- clock ---------------------------------------------------------------------------------
    def now(self) -> float:
        return (time.perf_counter_ns() - self._t0) / 1e9

    def _stamp(self, ns: int) -> float:
        return (ns - self._t0) / 1e9

    def timing_uncertainty(self) -> float:
        """What this link's stamps are worth so far (s): declared floor or measured."""
        return self.meter.uncertainty()

    def widen(self, uncertainty: float | None) -> None:
        """The user's figure goes to the meter, which reports it as the reason when it is
        what decides a stamp's worth."""
        super().widen(uncertainty)
        self.meter.widen_to = self.widened

    def uncertainty_between(self, start: float, end: float) -> float:
        """What a measurement between two instants is worth (s): more than
        :meth:`timing_uncertainty` where the run saw its stamps irregular near them."""
        return self.meter.between(start, end)

    def read_grace(self) -> float:
        """How long past its limit a read waits for characters stamped as started by then
        (s). A byte's stamp ends at its arrival or later (:func:`~.stamps.chunk_frames`), so
        the first of k bytes that came under one stamp starts at most k frames before the
        host had it: the frames of the most bytes seen under one stamp, and the declared
        floor for a byte the kernel has stamped that the reader thread has not handed over
        yet. Not the link's latency bound (the worst write to echo): that is how late a
        byte arrives after its stop bit, which its arrival stamp already carries; behind a
        16 ms latency timer it made the grace of every read that ran to its deadline 24.7
        ms where the stamps need 13.3 (21.7 where two bytes ever came under one stamp;
        issue 22, usb12). Bytes that came in a burst, each under its own stamp, are a frame each:
        they widen the stamps' uncertainty, not this."""
        return self._widest_chunk * CHAR_TIME + self.info.timing_uncertainty

    def latency_bound(self) -> float:
        """How long a byte may take to reach the reader after its stop bit (s)."""
        return max(self.info.timing_uncertainty, self.meter.round_trip.value)

    # -- reader thread -------------------------------------------------------------------------
    def _read_loop(self) -> None:
        self.realtime_priority = realtime_priority(READER)
        port = self.port
        back = time.perf_counter_ns()  # when the last read returned
        while not self._closing.is_set():
            asked = time.perf_counter_ns()
            try:
                data = port.read(max(1, port.in_waiting))
            except Exception as exc:  # pyserial raises SerialException, OSError, TypeError...
                if not self._closing.is_set():
                    with self._cond:
                        self._failure = exc
                        self._cond.notify_all()
                return
            arrival = time.perf_counter_ns()
            # no read returns later than its timeout after the last one came back unless the
            # whole process was held up: the host stalled (host_stall), said after what came
            stall = (arrival - back) / 1e9 - READ_POLL
            back = arrival
            if not data:  # a timed-out read: how late did the thread get back?
                overrun = (arrival - asked) / 1e9 - READ_POLL
                if 0 < overrun < 10 * READ_POLL:
                    self.meter.reader_lag.add(overrun, "idle read")
                self._host_stalled(stall, arrival)
                self._reader_back = arrival
                continue
            stamps = self._tape.take(len(data)) if self._tape is not None else None
            if stamps is not None:
                self.meter.reader_lag.add((arrival - max(stamps)) / 1e9, "kernel stamp")
                self._arrived(data, self._stamp(arrival), [self._stamp(s) for s in stamps])
            else:
                self._arrived(data, self._stamp(arrival))
            self._host_stalled(stall, arrival)
            self._reader_back = arrival

    def reader_caught_up(self) -> None:
        """Wait, where the reader thread is overdue (no turn of it finished within its read's
        timeout and :data:`~.host_stall.STALL_MIN`: the process was held up and the reader
        has not run since), until it is back, its note of the stall written. After a pause
        every thread resumes together, and the engine's read, cut by it, may hand its record
        over before the reader has said the host stalled (truth27). Not overdue: no wait; at
        most :data:`CATCH_UP` s."""
        overdue = int((READ_POLL + STALL_MIN) * 1e9)
        deadline = time.perf_counter_ns() + int(CATCH_UP * 1e9)
        while self._reader.is_alive() and time.perf_counter_ns() - self._reader_back > overdue:
            if time.perf_counter_ns() > deadline:
                return
            time.sleep(0.001)

    def _host_stalled(self, stall: float, arrival: int) -> None:
        """Note a stall of the tool's own host (:mod:`.host_stall`) of ``stall`` s that
        ended at ``arrival`` (ns), after the characters it held back."""
        if stall > STALL_MIN:
            with self._cond:
                self.transcript.note(self._stamp(arrival), stall_note(stall))

    def _arrived(self, data: bytes, arrival: float, stamps: list[float] | None = None) -> None:
        """Bytes read at ``arrival`` (``stamps``: the kernel's, one per byte, if known)."""
        with self._cond:
            for chunk, at in _chunks(data, stamps or [arrival] * len(data)):
                for byte, end in zip(chunk, self._frame_ends(chunk, at), strict=True):
                    if end > at:
                        self._note_pushed(end, at)
                    for heard in self.echo.heard(byte, end):
                        self._record(heard)
            self._cond.notify_all()

    def _note_pushed(self, end: float, arrival: float) -> None:
        """Keep that the frame stamped to end at ``end`` had reached the host at ``arrival``
        (caller holds the lock); the oldest go once :data:`PUSHED_KEPT` are kept."""
        pushed = self._pushed
        pushed[end] = arrival
        if len(pushed) > PUSHED_KEPT:
            del pushed[next(iter(pushed))]

    def received_by(self, end: float) -> float:
        """The latest the received character whose stamp ends at ``end`` can have ended on
        the wire: a byte is whole on the wire before the host has it, so where the
        no-overlap rule (:func:`~.stamps.chunk_frames`) placed its frame after its arrival,
        the arrival; else the stamp's end. Behind a 16 ms latency timer the replies come two
        characters a tick, 16.67 ms of frames in 16 ms, and the rule pushed a reply's last
        character 0-16 ms past its arrival (issue 22, usb12): a turnaround counted from
        that stamp waited that much more than the sensor's release (R-7.0-11) asks."""
        with self._cond:
            return min(end, self._pushed.get(end, end))

    def _frame_ends(self, chunk: bytes, arrival: float) -> list[float]:
        """Stop-bit ends of bytes that reached the host together, and what that shows about
        the stamps (caller holds the lock).

        Bytes that arrive together, or closer together than one wire can carry them, were
        held somewhere on the way; when the first of them really ended is then unknown: as
        early as right after the byte before them. So the marking measured before such a
        burst, and any gap hidden inside it, may be off by that whole room: the stamps there
        are tainted by it. A frame pushed past the previous one is an artefact of the same
        kind (one of the two stamps is wrong by the overlap)."""
        count = len(chunk)
        floor = self._rx_floor
        room = max(0.0, arrival - count * CHAR_TIME - floor)  # marking the stamps show before
        # the path's latency range as measured so far: irregularities within it are covered
        # by the run's regular figure; beyond it they are evidence of their own
        jitter = max(self.meter.regular(), ECHO_FLOOR)
        if count > 1:
            self._widest_chunk = max(self._widest_chunk, count)
            hidden = (count - 1) * CHAR_TIME
            self.meter.batches.add(hidden, f"{count} bytes at once")
            self.meter.taint(
                floor - CHAR_TIME, arrival, room + hidden + 2 * jitter, f"{count} bytes at once"
            )
        prev_floor, prev_room, prev_arrival = self._previous_chunk
        early = count * CHAR_TIME - (arrival - prev_arrival)  # how much sooner than a wire can
        if early > 2 * jitter + BURST_MARGIN:
            # this chunk came too soon after the previous one: that one was held back
            self.meter.batches.add(early, "bytes in a burst")
            self.meter.taint(
                prev_floor - CHAR_TIME,
                arrival,
                prev_room + early + 2 * jitter,
                "bytes reached the host in a burst",
            )
        pushed = overlap(count, arrival, floor)
        if pushed > 0:
            self.meter.artefacts.add(pushed, f"frames overlapping by {pushed * 1e3:.2f} ms")
        if pushed > 0 and self._last_origin == "tool" and not self.echo.pending:
            # after the tool's whole echo any overlap is proof, not jitter: a reply cannot
            # start before a command that came back intact ended, so one of the two stamps
            # is wrong by more than the overlap, by how much more nothing here shows. The
            # placement at the echo's end is the clamp's, not a measurement: the gap between
            # command and reply is unknown by a whole character beside the path's range (a
            # reply start measured as 0 ms would otherwise FAIL R-7.0-09).
            self.meter.taint(
                floor - 2 * CHAR_TIME,
                arrival,
                pushed + CHAR_TIME + 2 * jitter,
                "a reply overlapped the echo of the command",
            )
        elif pushed > jitter:
            # the frame is placed after the previous one; where it really was, the path's
            # latency range further hides: its stamps may be off by both
            self.meter.taint(floor - 2 * CHAR_TIME, arrival, pushed + jitter, "frames overlapped")
        frames = chunk_frames(count, arrival, floor)
        self._rx_floor = frames[-1][1]
        self._previous_chunk = (floor, room, arrival)
        return [end for _start, end in frames]

    def _record(self, heard: Heard) -> None:
        """Put one sorted byte in the transcript (caller holds the lock)."""
        self._last_origin = heard.origin
        expected = heard.expected
        if heard.origin == "tool" and expected is not None and not _is_char(expected):
            # a break or a UART-timed pulse read back: a line state, not a character
            self._state_echoes.append(heard.end)
            self.transcript.note(
                heard.end, f"the tool's spacing came back as 0x{heard.byte:02X} (echo)"
            )
            return
        if heard.origin == "tool":
            frame = expected.frame if expected is not None else CHAR_TIME
            event = Event(
                EventKind.CHAR,
                TOOL,
                heard.end - frame,
                heard.end,
                wire=heard.byte,
                text="echo",
                uncertainty=self.meter.uncertainty(),
            )
            self.transcript.add(event)
            self._echoed.append(event)
            return
        if not self.echo.echoes:
            self._flush_planned()  # the command the DUT answers goes in first
        if heard.note:
            self.transcript.note(heard.end, heard.note)
        event = Event(
            EventKind.CHAR,
            DUT,
            heard.end - CHAR_TIME,
            heard.end,
            wire=heard.byte,
            text=COLLISION if heard.collided else "",
            uncertainty=self.meter.uncertainty(),
        )
        self.transcript.add(event)
        if not heard.collided:  # what met the tool's own characters is no reply to read
            self._rx.append(event)

    def _check(self) -> None:
        """Raise if the port failed (called with or without the lock; reads one attribute)."""
        failure = self._failure
        if failure is not None:
            raise PortVanished(
                f"the port {self.name} failed during the run ({type(failure).__name__}: "
                f"{failure}). Check the cable, the adapter's power, or the server at the other "
                "end; the report up to this point was kept."
            ) from failure

    # -- tool side -----------------------------------------------------------------------------
    def wait_until(self, time_s: float) -> None:
        self._check()
        precise_sleep_until(self.now, time_s)

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        self._check()
        if not wire:
            return []
        with self._cond:
            self.echo.expect([Expected(b, CHAR_TIME) for b in wire])
        self._drive()
        planned: list[Event] = []
        if gap <= 0:
            start = max(self.now(), self._tx_free)
            self._port_write(wire)
            planned = [self._planned(b, start + k * CHAR_TIME) for k, b in enumerate(wire)]
        else:
            for byte in wire:
                precise_sleep_until(self.now, self._tx_free + (gap if planned else 0.0))
                start = max(self.now(), self._tx_free)
                self._port_write(bytes([byte]))
                planned.append(self._planned(byte, start))
        with self._cond:
            if self.echo.listening:
                self._planned_pending = planned
            else:
                for e in planned:
                    self.transcript.add(e)
        self._release_at(planned[-1].end)
        self.wait_until(planned[-1].end)
        events = self._settle_echo(planned, back_to_back=gap <= 0)
        self._released(planned[-1].end)
        return events

    def _tool_char(self, byte: int, start: float) -> Event:
        """A tool character recorded where the write put it (links without echo)."""
        event = self._planned(byte, start)
        with self._cond:
            self.transcript.add(event)
        return event

    def _planned(self, byte: int, start: float) -> Event:
        """A tool character where the write put it (before any echo says better)."""
        self._tx_free = start + CHAR_TIME
        return Event(
            EventKind.CHAR,
            TOOL,
            start,
            start + CHAR_TIME,
            wire=byte,
            uncertainty=self.info.timing_uncertainty,
        )

    def _settle_echo(self, planned: list[Event], *, back_to_back: bool = True) -> list[Event]:
        """Wait (bounded) for the echo of what was just sent and return the tool's events:
        the echoed ones, stamped on the receive path, or (no echo) the planned ones."""
        with self._cond:
            if self.echo.listening:
                wait = ECHO_WAIT if self.echo.decided else ECHO_WAIT_AUTO
                deadline = planned[-1].end + self.latency_bound() + wait
                while self.echo.pending and self.echo.listening and self.now() < deadline:
                    self._check()
                    self._cond.wait(min(deadline - self.now(), READ_POLL))
                if self.echo.pending:
                    for note in self.echo.expire():
                        self.transcript.note(self.now(), note)
                    for heard in self.echo.release():
                        self._record(heard)
            self.meter.echo = self.echo.echoes
            echoed, self._echoed = self._echoed, []
            self._state_echoes.clear()
            if not self.echo.echoes:
                self._flush_planned()
                return planned
            self._planned_pending = []  # the echoes stand for them
            self._measure_echo(planned, echoed, back_to_back)
            missing = planned[len(echoed) :]  # not heard back: where the write put them
            for e in missing:
                self.transcript.add(e)
            return echoed + missing

    def _flush_planned(self) -> None:
        """Record the tool's characters as written (caller holds the lock)."""
        for e in self._planned_pending:
            self.transcript.add(e)
        self._planned_pending = []

    def _measure_echo(self, planned: list[Event], echoed: list[Event], back_to_back: bool) -> None:
        """Echoed characters left the UART back to back: their spread about that spacing is
        the receive path's jitter; their delay after the write is its (fixed) latency."""
        chars = [e for e in echoed if abs(e.duration - CHAR_TIME) < 1e-9]
        if len(chars) != len(planned) or not chars:
            return
        offsets = [e.end - k * CHAR_TIME for k, e in enumerate(chars)]
        text = "".join(chr(e.char7) for e in chars)
        if len(chars) > 1 and back_to_back:
            spread = max(offsets) - min(offsets)
            self.meter.spread(chars[0].start, chars[-1].end, spread, f"echo of {text!r}")
        trip = chars[-1].end - planned[-1].end
        typical = self.meter.typical_round_trip()
        self.meter.round_trip.add(trip, f"echo of {text!r}")
        self.meter.trips.append(trip)
        if typical is not None and trip - typical > self.meter.uncertainty():
            # the whole echo came late: the command's end, as heard, is late by that much
            self.meter.taint(
                chars[0].start,
                chars[-1].end + RESPONSE_START_MAX,
                trip - typical,
                "the echo of the command came late",
            )

    def _port_write(self, data: bytes) -> None:
        try:
            self.port.write(data)
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()

    def _drive(self) -> None:
        """Raise the transmit-enable line (if the bench has one) before the tool sends."""
        if self._direction is None:
            return
        try:
            self._direction.set(True)
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()

    def _release_at(self, last_stop: float) -> None:
        """Have the driver released right after the last stop bit (by the timer thread)."""
        if self._release is not None:
            self._release.schedule(last_stop + RELEASE_MARGIN)

    def _released(self, last_stop: float) -> None:
        """Wait for the release and measure the turnaround it added. A release so late that
        the sensor may already have started its reply means the start of that reply may be
        lost under the tool's own driver: the stamps there are tainted by it."""
        if self._release is None or self._direction is None:
            return
        try:
            at = self._release.wait(RELEASE_WAIT)
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()
            return
        if at is None:
            at = self.now()
            self._direction.set(False)
        turnaround = max(0.0, at - last_stop)
        self.meter.turnaround.add(turnaround, self._direction.line)
        if turnaround > TURNAROUND_LIMIT:
            with self._cond:
                self.transcript.note(
                    at,
                    f"driver released {turnaround * 1e3:.2f} ms after the last stop bit: the "
                    "start of a reply may have been lost under it",
                )
            self.meter.taint(
                last_stop, at + RESPONSE_START_MAX, RESPONSE_START_MAX, "late driver release"
            )

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        self._check()
        pulse = self._pulse if exact and self._pulse is not None else None
        pulse = pulse if pulse is not None and pulse.can_make(duration) else None
        if pulse is None and (self._breaker is None or not self.info.can_break):
            note = f"no break: a {self.info.kind} link cannot hold the line spacing"
            with self._cond:
                self.transcript.note(self.now(), note)
            raise BreakUnsupported(note)
        precise_sleep_until(self.now, self._tx_free)
        self._drive()
        event = None
        if pulse is not None:
            try:
                event = self._uart_pulse(pulse, duration)
            except PulseRefused as exc:  # the far end does not change its bit rate
                self._pulse = None
                with self._cond:
                    self.transcript.note(
                        self.now(), f"{exc}: breaks are timed by the host from here on"
                    )
                if self._breaker is None:
                    raise BreakUnsupported(str(exc)) from exc
        if event is None:
            event = self._held_break(duration)
        with self._cond:
            self.transcript.add(event)
        self._release_at(event.end)
        self._released(event.end)
        return event

    def _held_break(self, duration: float) -> Event:
        """Spacing held by the host for ``duration`` (break_condition / SET_CONTROL)."""
        assert self._breaker is not None
        with self._cond:
            self.echo.expect([Expected(None, duration)])
        try:
            start = self.now()
            self._breaker.on()
            precise_sleep_until(self.now, start + duration)
            end = self.now()
            self._breaker.off()
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()
            raise
        self._tx_free = end
        text = (
            f"break asked {duration * 1e3:.2f} ms, held {(end - start) * 1e3:.2f} ms "
            f"({self._breaker.method}, timed by the host)"
        )
        return Event(
            EventKind.BREAK,
            TOOL,
            start,
            end,
            text=text,
            uncertainty=self.meter.uncertainty(),
        )

    def _uart_pulse(self, pulse: BaudPulse, duration: float) -> Event:
        """Spacing timed by the UART: a NUL at the bit rate whose 9 spacing bits last about
        ``duration`` (start bit and 8 zero data bits), then back to 1200 baud."""
        baud = pulse.baud_for(duration)
        frame = 10 / baud
        with self._cond:
            self.echo.expect([Expected(0x00, frame)])
        pulse.rate(baud)  # confirmed by the far end before anything is sent at that rate
        try:
            start = max(self.now(), self._tx_free)
            pulse.send_nul()
            self._tx_free = start + frame
            precise_sleep_until(self.now, start + frame + pulse.settle)
            # the echo (if any) must be in before the rate changes back: read at the usual
            # rate it would be a stray character. A lost echo costs ECHO_WAIT; the probe that
            # needed the pulse then lands late and is sent again (SensorSession.probe).
            with self._cond:
                deadline = start + frame + self.latency_bound() + ECHO_WAIT
                while self.echo.pending and self.echo.echoes and self.now() < deadline:
                    self._cond.wait(min(deadline - self.now(), READ_POLL))
            pulse.restore()
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()
            raise
        with self._cond:
            heard, self._state_echoes = self._state_echoes, []
            if self.echo.echoes and self.echo.pending:
                for note in self.echo.expire():
                    self.transcript.note(self.now(), note)
        spacing = 9 / baud
        if heard:  # the NUL's stop bit as heard: the pulse sits just before it
            start = heard[-1] - frame
        text = (
            f"spacing asked {duration * 1e3:.2f} ms, made {spacing * 1e3:.3f} ms: a NUL at "
            f"{baud} baud, timed by the UART ({pulse.method})"
        )
        return Event(
            EventKind.BREAK,
            TOOL,
            start,
            start + spacing,
            text=text,
            uncertainty=self.meter.uncertainty(),
            duration_uncertainty=spacing * pulse.rate_error,
        )

    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        """As :meth:`Link.receive`. A byte is seen only after its stop bit, so a read whose
        limit lies ahead waits :meth:`read_grace` past it for characters that started in
        time; one whose limit has already passed returns what is queued at once."""
        got: list[Event] = []
        grace = self.read_grace()
        waits = deadline > self.now()
        with self._cond:
            while True:
                limit = deadline
                if idle is not None and got:
                    limit = min(limit, got[-1].end + idle)
                while self._rx and self._rx[0].start < limit:
                    got.append(self._rx.popleft())
                    if until is not None and until(got):
                        return got
                    if idle is not None:
                        limit = min(deadline, got[-1].end + idle)
                later_char_queued = bool(self._rx)  # it started after the limit: we are done
                now = self.now()
                if later_char_queued or not waits or now >= limit + grace:
                    return got
                self._check()
                self._cond.wait(min(limit + grace - now, 0.1))

    def _break_methods(self) -> str:
        """How this link makes line states, for the report."""
        held = f"host-timed ({self._breaker.method})" if self._breaker else ""
        if self._pulse is None:
            return held or "none (the link cannot hold the line spacing)"
        pulses = f"UART-timed near thresholds ({self._pulse.method})"
        return f"{pulses}, wake-ups {held}" if held else pulses

    def describe(self) -> dict[str, object]:
        """What the report's link section shows about this bench."""
        found = {
            "echo": self.echo.echoes,
            "echo_mode": str(self.echo.mode),
            "echo_collisions": self.echo.collisions,
            "echo_missing": self.echo.missing,
            "breaks": self._break_methods(),
            "direction": self._direction.line if self._direction else "none",
            "realtime_reader": self.realtime_priority,
        }
        return found | {"timing": self.meter.to_json()}

    def close(self) -> None:
        self._closing.set()
        with contextlib.suppress(Exception):  # closing a vanished port must not mask the result
            self.port.close()
        self._reader.join(timeout=1.0)
        if self._release is not None:
            self._release.close()
        sys.setswitchinterval(self._switch_interval)


def _is_char(expected: Expected) -> bool:
    """A 1200-baud character (not spacing, not a pulse made at another bit rate)."""
    return expected.byte is not None and abs(expected.frame - CHAR_TIME) < 1e-9


def _chunks(data: bytes, stamps: list[float]) -> list[tuple[bytes, float]]:
    """Bytes grouped by equal arrival stamp (one packet, or one read), in order."""
    out: list[tuple[bytes, float]] = []
    for byte, at in zip(data, stamps, strict=True):
        if out and out[-1][1] == at:
            out[-1] = (out[-1][0] + bytes([byte]), at)
        else:
            out.append((bytes([byte]), at))
    return out
