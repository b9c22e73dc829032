"""The reference SDI-12 sensor: a sans-I/O state machine driven only by stamped bus events.

The emulator never reads a clock. It hears breaks and characters with their start and end
times (seconds on whatever clock the driver uses: the sim bus's virtual clock, or a real-time
RFC 2217 server later) and offers its own output as frames with start times. Every idle-time
rule of section 7 (standby after 100 ms of marking, 8.33 ms after a break, partial commands) is
therefore computed from the gaps between stamps when the next stamp arrives.

Line model:
- A fresh emulator is in standby; only a break wakes it.
- Spacing of at least ``break_threshold`` (9 ms) is a break; shorter spacing is noise that
  spoils a command being received but wakes nothing (R-7.0-03/04).
- The first character after a break must start at least 8.33 ms (-0.40) after it, otherwise
  that command is ignored (R-7.0-05).
- Line activity is any character on the wire (including the emulator's own) or a break.
  100 ms of marking since the last activity means standby (R-7.0-15); a command for another
  address means standby at once (R-7.0-14). Standby is left only through a break; sending a
  service request also leaves the sensor listening, so ``aD0!`` may follow it without a
  break (R-7.1-02).
- Inside a command, 8.33 ms (-0.40) of marking before the next character drops the partial
  command; that character starts a new one (R-AppB-01).

Measurement model: any valid command for this sensor that arrives while a measurement is
running aborts it (R-4.4.7.1-01 for C/HA/HB; for M/V it can only happen without a break in
the 100 ms after ``atttn``). A break aborts M/V before its service request (R-4.4.5.1-01)
but not C/HA/HB (R-4.4.7-05). Aborted or still-running measurements answer D with the empty
reply, never partial data (decision A3).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace
from math import inf
from typing import Any

from ..protocol.binary import DataType, encode_values
from ..protocol.commands import (
    ADDRESS_CHARS,
    SERVICE_REQUEST_KINDS,
    V14_ONLY_KINDS,
    Command,
    CommandError,
    Kind,
    count_digits,
    parse_command,
)
from ..protocol.framing import COMMAND_END, CRLF, STX, TEXT_END
from ..sim.bus import Frame
from ..transcript import parity_bit
from .behaviour import Behaviour
from .faults import compose
from .measurement import DataSet, Run, complete, empty_data
from .profile import MeasurementSpec, Profile
from .replies import BinaryParts, Reply, ReplyKind
from .transmitter import Transmission, Transmitter

#: The replies :attr:`Behaviour.stray_after_line_end` follows: two that close their exchange
#: at their CR LF (``engine.closes_exchange``), a data page and the identification.
_STRAY_AFTER = frozenset({ReplyKind.DATA, ReplyKind.IDENTIFICATION})
#: the command kinds every command is dispatched by, as module constants (``_dispatch``)
_ACKNOWLEDGE, _QUERY_ADDRESS, _IDENTIFY = Kind.ACKNOWLEDGE, Kind.QUERY_ADDRESS, Kind.IDENTIFY
_CHANGE_ADDRESS, _DATA, _BINARY_DATA = Kind.CHANGE_ADDRESS, Kind.DATA, Kind.BINARY_DATA
_CONTINUOUS, _IDENTIFY_MEASUREMENT = Kind.CONTINUOUS, Kind.IDENTIFY_MEASUREMENT
_METADATA, _EXTENDED = Kind.METADATA, Kind.EXTENDED
_SERVICE_REQUEST, _CHATTER = ReplyKind.SERVICE_REQUEST, ReplyKind.CHATTER  # (``_sent``)
_MAX_COMMAND = 64  # a command longer than this is noise; drop it rather than grow forever
#: a 7-bit character's text and even parity bit, looked up per character heard (``on_char``)
_CHR7 = tuple(map(chr, range(0x80)))
_PARITY = tuple(map(parity_bit, range(0x80)))


class SensorEmulator:
    """A conforming SDI-12 sensor (v1.4, or v1.3 by profile) on a :class:`SimBus`-like driver.

    ``faults`` names entries of :data:`conformance.emulator.faults.FAULTS`; they are applied in
    order (later settings win, rewrites chain).
    """

    def __init__(
        self,
        profile: Profile,
        faults: Sequence[str] = (),
        name: str = "sensor",
        quirks: Mapping[str, Any] | None = None,
    ) -> None:
        self.name = name
        self.faults = compose(faults)
        self.profile = self.faults.apply_profile(profile)
        # legal quirks of a firmware profile first, so that a fault's deviation still shows
        base = replace(Behaviour(), **dict(quirks or {}))
        self.behaviour = replace(base, **dict(self.faults.behaviour_settings))
        self.address = self.profile.address
        self._old_addresses: set[str] = set()
        self._tx = Transmitter()
        # line state
        self._awake = False
        self._last_activity = -inf
        self._wake_at = -inf
        self._waking = False  # woke up after a delay and has not taken a command yet
        self._breaks = 0  # breaks heard: which of them the slow wake of every other one takes
        self._break_end: float | None = None
        self._buf: list[str] = []
        self._buf_start = 0.0
        self._buf_end = 0.0
        self._buf_invalid = False
        self._buf_foreign = False
        self._quiet_until = -inf
        self._deaf = False
        # measurement state
        self._run: Run | None = None
        self._data: DataSet | None = None
        self._previous: DataSet | None = None
        self._last_command: Command | None = None
        self._measured: set[str] = set()  # M/V commands started before (a faulty sensor's)
        #: per M command, whether its last start ran to completion (a faulty sensor's)
        self._completed: dict[str, bool] = {}
        self._crc_stuck = False  # only a faulty sensor sets it (metadata_crc_sticks)
        self._replied_last = False  # the last thing on the line was this sensor's own
        self._report: Transmission | None = None  # only a faulty sensor sets it (abort_reply)
        self._overheard = ""  # the last two characters heard (a bus fault's CR LF)
        #: the command whose reply went out after a break of the sensor's own (only a faulty
        #: sensor sets it: break_before_reply): its later lines follow without one
        self._spaced_for: Command | None = None

    # -- introspection (tests, CLI) ----------------------------------------------------------
    @property
    def data(self) -> DataSet | None:
        """The data buffer (None before the first measurement or while one runs)."""
        return self._data

    @property
    def running(self) -> Run | None:
        return self._run

    def awake(self, now: float) -> bool:
        """Whether a command starting at ``now`` without a break would be heard."""
        reference = max(self._last_activity, self._wake_at)
        return self._awake and now >= self._wake_at and now - reference < self._standby_limit

    @property
    def _standby_limit(self) -> float:
        after_reply = self.behaviour.standby_after_reply_marking
        if after_reply is not None and self._replied_last:
            return after_reply  # a faulty sensor: sooner asleep after its own reply
        return self.behaviour.standby_marking

    # -- BusDevice: input --------------------------------------------------------------------
    def on_break(self, start: float, end: float) -> None:
        b = self.behaviour
        self._settle(start)
        idle_before = start - max(self._last_activity, self._wake_at) >= self._standby_limit
        if end - start < b.break_threshold:
            # too short for a break: noise on the line that ruins a command in progress;
            # the marking before it may already have sent the sensor to standby (R-7.0-15)
            if self._awake and idle_before:
                self._awake = False
                self._entered_standby()
            self._last_activity = max(self._last_activity, end)
            if self._buf:
                self._buf_invalid = True
            return
        if idle_before or not self._awake:
            self._entered_standby()
        self._deaf = False
        run = self._run
        if run is not None:
            aborts = b.break_aborts_concurrent if run.concurrent else b.break_aborts_measure
            if aborts:
                self._abort()
        # a break silences the sensor; only the service request of a still-running
        # measurement survives it
        running = self._run is not None
        self._tx.cancel(
            lambda t: (
                (running and t.reply.kind is ReplyKind.SERVICE_REQUEST and t.sent == 0)
                or t is self._report
            )  # what a faulty firmware says of the measurement it aborted
        )
        data = self._data
        if b.clear_on_break_after_read and data is not None and data.fully_read:
            self._data = data.emptied()
        self._awake = True
        self._breaks += 1
        delay = 0.0 if b.wake_every_other and self._breaks % 2 else b.wake_delay
        self._wake_at = end + delay
        self._waking = delay > 0
        self._break_end = end
        self._last_activity = end
        self._replied_last = False
        self._buf = []
        self._overheard = ""

    def on_char(self, wire: int, start: float, end: float) -> None:
        # Heard once per tool character (some 5,500 a fault-matrix row, issue 22), so the
        # calls it made per character are spelt out here: ``_tx.line_taken_until`` only
        # where something is planned (it returns at once on an empty queue), ``_settle``,
        # ``_hear``, ``max`` (as ``max(a, b)`` picks: ``b`` only if ``b > a``) and
        # ``parity_bit``; the same state changes in the same order.
        b = self.behaviour
        tx = self._tx
        if tx.queue:
            tx.line_taken_until(end)  # a frame of ours planned inside it waits for it
        report = self._report
        if report is not None and report.sent == 0:
            # the firmware reports an aborted measurement only to a line left quiet
            self._tx.cancel(lambda t: t is not report)
            self._report = None
        run = self._run
        if run is not None and run.ready_at <= start:  # _settle(start)
            self._complete(run)
        if b.foreign_reply_aborts_concurrent or b.answer_foreign_reply:
            self._overhear(_CHR7[wire & 0x7F], end)
        previous = self._last_activity
        # _hear(start): the idle rules at a start bit
        wake_at = self._wake_at
        if start < wake_at:
            heard = False  # still waking up after the break
        else:
            reference = wake_at if wake_at > previous else previous
            if self._awake and start - reference >= self._standby_limit:
                self._awake = False  # R-7.0-15: 100 ms of marking
                self._entered_standby()
            heard = self._awake
        last = self._last_activity
        if end > last:
            self._last_activity = end
        self._replied_last = False
        if not heard:
            self._buf = []
            return
        char7 = wire & 0x7F
        char = _CHR7[char7]
        buf = self._buf
        if buf and start - self._buf_end >= b.partial_gap:
            buf = self._buf = []  # R-AppB-01: marking inside a command drops it
        if not buf:
            # a sensor that woke up while characters were flowing has caught the tail of a
            # command: like after a break, it needs marking before it takes an address
            mid_stream = self._waking and start - previous < b.address_marking
            self._waking = False
            self._begin_command(char, start, mid_stream)
            if not self._awake:
                return
            buf = self._buf
        buf.append(char)
        self._buf_end = end
        if (wire >> 7) != _PARITY[char7]:
            self._buf_invalid = True  # a parity error spoils the command
        if char == COMMAND_END:
            text, invalid, begun = "".join(self._buf), self._buf_invalid, self._buf_start
            foreign = self._buf_foreign
            self._buf = []
            if not invalid:
                self._command(text, begun, end, foreign)
        elif len(self._buf) > _MAX_COMMAND:
            self._buf = []

    def _overhear(self, char: str, end: float) -> None:
        """What only a faulty sensor on a bus of several does with another sensor's reply (its
        CR LF: the tool's commands end in '!') heard while its own concurrent measurement runs:
        drop the measurement, or answer the reply with its address as if it were a command."""
        self._overheard = (self._overheard + char)[-2:]
        run = self._run
        if self._overheard != "\r\n" or run is None or not run.concurrent:
            return
        if self.behaviour.foreign_reply_aborts_concurrent:
            self._abort()
        if self.behaviour.answer_foreign_reply:
            reply = Reply(ReplyKind.CHATTER, self.address, source=run.command)
            self._send(reply, end + self.behaviour.reply_delay)

    def _hear(self, start: float) -> bool:
        """Apply the idle rules at a start bit; False if the sensor cannot hear it."""
        if start < self._wake_at:
            return False  # still waking up after the break
        reference = max(self._last_activity, self._wake_at)
        if self._awake and start - reference >= self._standby_limit:
            self._awake = False  # R-7.0-15: 100 ms of marking
            self._entered_standby()
        return self._awake

    def _begin_command(self, char: str, start: float, mid_stream: bool = False) -> None:
        b = self.behaviour
        early = self._break_end is not None and start - self._break_end < b.address_marking
        self._break_end = None
        # R-7.0-05: an address this soon after a break is not seen
        self._buf_invalid = early or mid_stream
        self._buf_start = start
        # a character the sensor could not take as an address says nothing about who is
        # addressed, so it neither selects nor deselects the sensor
        self._buf_foreign = not (self._buf_invalid or self._addressed(char))
        if not self._buf_foreign:
            return
        run = self._run
        if run is not None and run.concurrent and b.foreign_aborts_concurrent:
            self._abort()
        if b.standby_after_foreign and not (b.answer_foreign or self._reads_foreign_tail()):
            self._awake = False  # R-7.0-14
            self._entered_standby()

    def _reads_foreign_tail(self) -> bool:
        """Whether a foreign command is heard to its '!' before the sensor goes to standby
        (R-7.0-14): only to answer its tail (answer_trailing_address), never beside
        answer_foreign, which keeps its own standby rule."""
        b = self.behaviour
        return b.answer_trailing_address and b.standby_after_foreign and not b.answer_foreign

    def _addressed(self, char: str) -> bool:
        if char in (self.address, "?"):
            return True
        return self.behaviour.answer_old_address and char in self._old_addresses

    # -- BusDevice: output -------------------------------------------------------------------
    def next_frame(self) -> Frame | None:
        return self._tx.next_frame()

    def pop_frame(self) -> Frame:
        frame, item = self._tx.pop_frame()
        self._sent(frame.start + frame.duration, item)
        return frame

    # -- sim.bus.PlansFrames: a reply committed in one run ----------------------------------
    def frames_ahead(self) -> Iterator[tuple[float, int, float]] | None:
        return self._tx.ahead()

    def pop_frames(self, count: int) -> None:
        self._sent(*self._tx.pop_frames(count))

    def _sent(self, end: float, item: Transmission) -> None:
        """After a frame of ``item`` ending at ``end`` went out (the latest of several)."""
        self._last_activity = max(self._last_activity, end)
        self._replied_last = True
        if item.done:
            kind = item.reply.kind
            if kind is _SERVICE_REQUEST:
                self._awake = not self.behaviour.standby_after_service_request
            elif kind is not _CHATTER and self.behaviour.standby_after_reply:
                self._awake = False

    # -- measurement bookkeeping -------------------------------------------------------------
    def _settle(self, now: float) -> None:
        """Turn a running measurement into data once its ready time has passed."""
        run = self._run
        if run is not None and run.ready_at <= now:
            self._complete(run)

    def _complete(self, run: Run) -> None:
        """``run`` finished: its data in the buffer, nothing running."""
        self._data = complete(run, self.behaviour)
        self._run = None
        if self.behaviour.fewer_values_repeated:
            self._completed[run.command.text()] = True

    def _abort(self) -> None:
        run = self._run
        if run is None:
            return
        self._run = None
        self._tx.cancel_kind(ReplyKind.SERVICE_REQUEST)
        self._tx.cancel_kind(ReplyKind.CHATTER)
        if self.behaviour.abort_keeps_old_data:
            self._data = self._previous
        else:
            self._data = empty_data(run.command)
        if self.behaviour.deaf_after_abort:
            self._deaf = True
        if self.behaviour.abort_reply:
            text = run.command.address + self.behaviour.abort_reply
            self._report = self._send(
                Reply(ReplyKind.CHATTER, text, source=run.command), run.ready_at
            )

    def _entered_standby(self) -> None:
        data = self._data
        if self.behaviour.clear_on_standby_after_read and data is not None and data.fully_read:
            self._data = data.emptied()

    # -- commands ----------------------------------------------------------------------------
    def _command(self, text: str, start: float, end: float, foreign: bool) -> None:
        b = self.behaviour
        if foreign and self._reads_foreign_tail():
            self._awake = False  # R-7.0-14, put off to the '!' by answer_trailing_address
            self._entered_standby()
        try:
            cmd = parse_command(text)
        except CommandError:
            self._non_command(text, end, foreign)
            return  # decision A12: silence to what is not a command
        at = end + b.reply_delay
        if start < self._quiet_until or self._deaf:
            return  # deaf at every address: the any-address answer too (seed 4148)
        if foreign:
            if b.answer_foreign and cmd.kind in (Kind.ACKNOWLEDGE, Kind.IDENTIFY):
                self._dispatch(cmd, at)
                if b.standby_after_foreign:
                    self._awake = False
            elif b.answer_trailing_address and text[-2:-1] == self.address:
                self._send(Reply(ReplyKind.ACKNOWLEDGE, self.address, command=cmd), at)
            return
        if cmd.address == "?" and cmd.kind is not _QUERY_ADDRESS:
            return  # R-4.4.3-02: the wildcard is accepted only in ?!
        if cmd.kind is _QUERY_ADDRESS and not b.answer_query:
            return
        if not self.profile.v14 and cmd.kind in V14_ONLY_KINDS:
            return  # a v1.3 sensor does not know the command: silence
        run = self._run
        if run is not None and (not run.concurrent or b.command_aborts_concurrent):
            self._abort()  # R-4.4.7.1-01 (and M/V heard without a break)
        self._dispatch(cmd, at)
        self._last_command = cmd
        if b.deaf_until_reply:
            self._quiet_until = max(self._quiet_until, at)

    def _dispatch(self, cmd: Command, at: float) -> None:
        # the command's kind compared (``==``, as a ``match`` on ``case Kind.X`` compares)
        # with module constants: a ``case Kind.X`` reads the member off the enum, through its
        # metaclass's ``__getattr__`` hook on Python 3.11, at every case tried (issue 22,
        # matrix25: a metadata command tried nine)
        a = cmd.address if cmd.address != "?" else self.address
        kind = cmd.kind
        if kind == _ACKNOWLEDGE:
            self._send(Reply(ReplyKind.ACKNOWLEDGE, a, command=cmd), at)
        elif kind == _QUERY_ADDRESS:
            self._send(Reply(ReplyKind.ADDRESS, a, command=cmd), at)
        elif kind == _IDENTIFY:
            body = a + self.profile.identification()
            self._send(Reply(ReplyKind.IDENTIFICATION, body, command=cmd), at)
        elif kind == _CHANGE_ADDRESS:
            self._change_address(cmd, at)
        elif kind == _DATA:
            self._data_reply(cmd, at)
        elif kind == _BINARY_DATA:
            self._binary_reply(cmd, at)
        elif kind == _CONTINUOUS:
            self._continuous(cmd, at)
        elif kind == _IDENTIFY_MEASUREMENT:
            self._identify_measurement(cmd, at)
        elif kind == _METADATA:
            self._metadata(cmd, at)
        elif kind == _EXTENDED:
            text = self.profile.extended.get(cmd.body)
            if text is not None and "\n" in text:
                self._multiline(cmd, a, text.split("\n"), at)
            elif text is not None:
                self._send(Reply(ReplyKind.EXTENDED, a + text, command=cmd), at)
            else:
                self._unknown(cmd, at)
        else:
            self._start_measurement(cmd, at)

    def _non_command(self, text: str, end: float, foreign: bool) -> None:
        """What only a faulty sensor does with text that is not a command: take a character
        that is no address as its new address, or answer a wildcard it should not."""
        b = self.behaviour
        at = end + b.reply_delay
        if b.wildcard_answer and text[:1] == "?" and text != "?!":
            self._send(Reply(ReplyKind.ACKNOWLEDGE, self.address), at)
        elif (
            b.accept_any_new_address
            and not foreign
            and len(text) == 4
            and text[0] == self.address
            and text[1] == "A"
            and text[3] == COMMAND_END
        ) or (
            b.address_change_ignores_tail
            and not foreign
            and len(text) > 4
            and text[0] == self.address
            and text[1] == "A"
            and text[2] in ADDRESS_CHARS
        ):
            self._old_addresses.add(self.address)
            self.address = text[2]
            self._send(Reply(ReplyKind.CHANGE_ADDRESS, text[2]), at)

    def _unknown(self, cmd: Command, at: float) -> bool:
        """A command the sensor does not serve: a faulty firmware answers it with text of
        its own (``unknown_reply``) where the reference is silent or empty. True if sent."""
        text = self.behaviour.unknown_reply
        if not text:
            return False
        self._send(Reply(ReplyKind.CHATTER, cmd.address + text, command=cmd), at)
        return True

    def _multiline(self, cmd: Command, address: str, lines: list[str], at: float) -> None:
        """Multi-line text (4.4.13.1, decision A10): 'a<STX>' before the first line, CR LF
        after each, ETX after the last; lines ``line_gap`` apart, no CRC."""
        b = self.behaviour
        for n, line in enumerate(lines):
            body = (address + chr(STX) if n == 0 else "") + line[: b.line_limit]
            last = n == len(lines) - 1
            end = TEXT_END if last and b.etx else CRLF
            sent = self._send(Reply(ReplyKind.EXTENDED, body, command=cmd, end=end), at)
            if sent is None:
                return
            at = sent.end + b.line_gap

    def _send(self, reply: Reply, at: float) -> Transmission | None:
        rewritten = self.faults.rewrite(reply)
        if rewritten is None:
            return None
        b = self.behaviour
        pauses: tuple[tuple[int, float], ...] = ()
        if rewritten.kind is ReplyKind.IDENTIFICATION and b.ident_pause:
            pauses += ((b.ident_pause_at, b.ident_pause),)
        stray = b.stray_after_line_end
        if stray is not None and rewritten.kind in _STRAY_AFTER and rewritten.end == CRLF:
            # the stray character goes out in the same transmission, ``stray`` of marking
            # after the LF (a pause before its frame), so nothing can be scheduled between;
            # beside another fault's pause in the reply (ident-pause's in aI!'s), both hold
            pauses += ((len(rewritten.text()), stray),)
            rewritten = replace(rewritten, end=CRLF + b.stray_char)
        spacing = b.break_before_reply
        if spacing and reply.command is not None and reply.command is not self._spaced_for:
            # the first line of its reply to a command: the break from the command's end
            # (``at`` is reply_delay after it), the rest of reply_delay marking
            self._spaced_for = reply.command
            marking = max(b.reply_delay - spacing, 0.0)
            return self._tx.schedule(
                rewritten,
                at,
                b.char_gap,
                b.char_time,
                pauses=pauses,
                spacing=spacing,
                marking=marking,
            )
        return self._tx.schedule(rewritten, at, b.char_gap, b.char_time, pauses=pauses)

    def _change_address(self, cmd: Command, at: float) -> None:
        old, new = self.address, cmd.new_address
        if not self.profile.address_settable:
            new = old
        elif self.behaviour.apply_address_change:
            self.address = new
            if old != new:
                self._old_addresses.add(old)
        sent = self._send(Reply(ReplyKind.CHANGE_ADDRESS, new, command=cmd), at)
        if sent is not None:
            self._quiet_until = sent.end + self.profile.address_change_quiet

    # -- measurements ------------------------------------------------------------------------
    def _answers(self, cmd: Command, spec: MeasurementSpec | None) -> bool:
        """Whether a measurement (or its identify form) gets a reply at all."""
        if spec is not None or not cmd.group:
            return True
        if cmd.kind is Kind.MEASURE:
            return self.behaviour.answer_undefined_measure
        if cmd.kind is Kind.CONCURRENT:
            return self.behaviour.answer_undefined_concurrent
        return True

    def _start_reply(
        self, cmd: Command, target: Command, spec: MeasurementSpec | None, kind: ReplyKind
    ) -> Reply:
        digits = count_digits(target)
        ttt, count = (spec.ttt, spec.count) if spec is not None else (0, 0)
        body = f"{cmd.address}{ttt:03d}{count:0{digits}d}"
        return Reply(kind, body, command=cmd, source=target, digits=digits)

    def _start_measurement(self, cmd: Command, at: float) -> None:
        b = self.behaviour
        self._tx.cancel(lambda t: not (t.reply.kind is ReplyKind.CHATTER and t.sent == 0))
        spec = self._timed(cmd, self.profile.spec_for(cmd))
        if not self._answers(cmd, spec) or (spec is None and self._unknown(cmd, at)):
            return
        sent = self._send(self._start_reply(cmd, cmd, spec, ReplyKind.START), at)
        if sent is None:
            return
        spec = self._short_when_repeated(cmd, spec)  # announced in full, delivered short
        if spec is None and b.undefined_group_keeps_data:
            return  # a faulty sensor: the undefined group leaves the old data readable
        self._previous = self._data
        self._data = None
        delay = spec.ready_delay if spec is not None else 0.0
        quick = b.ready_after if cmd.kind in SERVICE_REQUEST_KINDS else None
        if spec is not None and spec.ttt and quick is not None:
            delay = min(delay, quick)  # a quirk: ready long before ttt
        run = Run(cmd, spec, sent.end + delay)
        if spec is None or spec.ttt == 0:
            self._complete(run)  # R-4.4.5-03: ready at once
            sr_kind = cmd.kind in SERVICE_REQUEST_KINDS
            if spec is not None and sr_kind and b.service_request_on_ttt_zero:
                self._service_request(cmd, sent.end + b.reply_delay)
            return
        self._run = run
        wants_sr = cmd.kind in SERVICE_REQUEST_KINDS or (
            cmd.is_concurrent and b.service_request_on_concurrent
        )
        if not wants_sr or not b.service_request:
            return
        sr_at = run.ready_at
        if b.service_request_late is not None and cmd.kind in SERVICE_REQUEST_KINDS:
            sr_at = sent.end + spec.ttt + b.service_request_late
        if (late := self._late_when_repeated(cmd)) is not None:
            sr_at = sent.end + spec.ttt + late
        if b.chatter_before_service_request:
            chatter = Reply(ReplyKind.CHATTER, cmd.address + "BUSY", source=cmd)
            self._send(chatter, (sent.end + run.ready_at) / 2)
        self._service_request(cmd, sr_at)

    def _late_when_repeated(self, cmd: Command) -> float | None:
        """How long after ttt a faulty sensor sends the service request of an M/V command it
        has measured before (``service_request_late_repeated``); None: when it is ready."""
        late = self.behaviour.service_request_late_repeated
        if late is None or cmd.kind not in SERVICE_REQUEST_KINDS:
            return None
        key = cmd.text()
        if key not in self._measured:
            self._measured.add(key)
            return None
        return late

    def _short_when_repeated(
        self, cmd: Command, spec: MeasurementSpec | None
    ) -> MeasurementSpec | None:
        """``spec``, or for an M command (the M family: aM!, aMC!, aMn!...) of two or more
        values whose last start since power-up ran to completion, the same count announced
        and its last value left out of the data (``fewer_values_repeated``, a faulty
        sensor's). The first of each delivers all, and so does one started after its last
        start was aborted (a break's abort case compares that one with the first, under its
        own rule): only a case that measures again sees the count fall short (truth35)."""
        if not self.behaviour.fewer_values_repeated or spec is None:
            return spec
        if cmd.kind is not Kind.MEASURE or len(spec.values) < 2:
            return spec
        key = cmd.text()
        again, self._completed[key] = self._completed.get(key, False), False
        return replace(spec, values=spec.values[:-1], announced=spec.count) if again else spec

    def _timed(self, cmd: Command, spec: MeasurementSpec | None) -> MeasurementSpec | None:
        """``spec`` with the ttt the behaviour announces (``announce_ttt``) for an M/V
        measurement with ttt > 0 when that is set; ready at that ttt unless ``ready_after``
        makes it sooner (:meth:`_measure`)."""
        announce = self.behaviour.announce_ttt
        if spec is None or not spec.ttt or announce is None:
            return spec
        if cmd.kind not in SERVICE_REQUEST_KINDS:
            return spec
        return replace(spec, ttt=announce, ready_after=None)

    def _service_request(self, source: Command, at: float) -> None:
        self._send(Reply(ReplyKind.SERVICE_REQUEST, source.address, source=source), at)

    def _identify_measurement(self, cmd: Command, at: float) -> None:
        b = self.behaviour
        target = cmd.target
        assert target is not None
        spec = self._timed(target, self.profile.spec_for(target))
        if not b.answer_identify_measurement or not self._answers(target, spec):
            return
        sent = self._send(self._start_reply(cmd, target, spec, ReplyKind.IDENTIFY), at)
        if b.identify_clears_data and self._data is not None:
            self._data = self._data.emptied()
        if (
            sent is not None
            and b.service_request_on_identify
            and spec is not None
            and spec.ttt > 0
            and target.kind in SERVICE_REQUEST_KINDS
        ):
            self._service_request(cmd, sent.end + spec.ready_delay)

    # -- data --------------------------------------------------------------------------------
    def _data_reply(self, cmd: Command, at: float) -> None:
        b = self.behaviour
        data = self._data
        if data is None:
            # nothing measured yet, or still measuring: no data (decision A3)
            data = empty_data(self._run.command if self._run else None)
        high_volume = data.source is not None and data.source.kind is Kind.HIGH_VOLUME_ASCII
        limit = min(data.max_index, b.max_data_index) if high_volume else data.max_index
        if cmd.index > limit:
            self._unknown(cmd, at)
            return  # D10+ exists only after HA; silence otherwise (decision A12)
        index = cmd.index
        if (
            b.groups_from_d1
            and data.source is not None
            and data.source.kind in (Kind.MEASURE, Kind.VERIFY)
        ):
            index -= 1  # a faulty sensor that starts its groups at D1
        in_range = 0 <= index < len(data.pages)
        page = "" if data.binary or not in_range else data.pages[index]
        repeat = data.note_read(index) if page else 0
        reply = Reply(
            ReplyKind.DATA,
            cmd.address + page,
            command=cmd,
            source=data.source,
            crc=data.crc or self._crc_stuck,
            repeat=repeat,
        )
        self._send(reply, at)
        if b.clear_after_read and data is self._data and data.fully_read:
            self._data = data.emptied()

    def _binary_reply(self, cmd: Command, at: float) -> None:
        data = self._data
        address = ord(cmd.address)
        if data is not None and data.binary and cmd.index < len(data.packets):
            dtype, values = data.packets[cmd.index]
            payload = encode_values(DataType(dtype), values)
            data.note_read(cmd.index)
            parts = BinaryParts(address, dtype, payload)
        elif self.behaviour.empty_packet:
            parts = BinaryParts(address, 0, b"")  # R-5.2-06
        else:
            return
        source = data.source if data is not None else None
        reply = Reply(ReplyKind.BINARY, cmd.address, command=cmd, source=source, binary=parts)
        self._send(reply, at)

    def _continuous(self, cmd: Command, at: float) -> None:
        spec = self.profile.spec_for(cmd)
        last = self._last_command
        if (
            self.behaviour.continuous_needs_r0
            and cmd.group > 0
            and not (last is not None and last.kind is Kind.CONTINUOUS and last.group == 0)
        ):
            spec = None
        if spec is None and self._unknown(cmd, at):
            return
        values = "".join(spec.values) if spec is not None else ""
        reply = Reply(
            ReplyKind.CONTINUOUS, cmd.address + values, command=cmd, source=cmd, crc=cmd.crc
        )
        self._send(reply, at)
        shared = spec is not None and self.behaviour.continuous_overwrites_data
        if shared and self._data is not None:
            self._data = self._data.emptied()  # a faulty sensor: R shares the D buffer

    def _metadata(self, cmd: Command, at: float) -> None:
        target = cmd.target
        assert target is not None
        spec = self.profile.spec_for(target)
        index = cmd.param
        body = cmd.address
        if spec is not None and 1 <= index <= min(spec.count, len(spec.metadata)):
            body += "," + ",".join(spec.metadata[index - 1]) + ";"
        elif not self.behaviour.metadata_invalid_reply:
            return
        reply = Reply(ReplyKind.METADATA, body, command=cmd, source=target, crc=target.returns_crc)
        self._send(reply, at)
        if target.returns_crc and self.behaviour.metadata_crc_sticks:
            self._crc_stuck = True  # a faulty sensor: the CRC request outlives its command
