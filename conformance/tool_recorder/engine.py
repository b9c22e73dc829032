"""The tool recorder: the tool's own data recorder, correct per section 7, that only records.

In the sensor role it is the stimulus that drives the device under test; in the recorder role
it is the "golden recorder" that other recorders are compared with. Either way it sends what a
correct recorder sends (breaks, retries, service-request waits, D0..Dn collection) and hands
back :mod:`~conformance.tool_recorder.records` with every attempt, leaving every verdict to judges.
It talks to the bus only through the :class:`~conformance.links.base.Link` API, so it runs the
same on the virtual-time sim bus and on a serial port, and every read is bounded by a
deadline so a silent or babbling device can never hang it.
"""

from __future__ import annotations

import contextlib
from itertools import repeat
from operator import attrgetter, is_

from ..links.base import LineEnd, Link
from ..links.errors import BreakUnsupported
from ..links.host_stall import noted_since_activity, settled_at
from ..protocol import commands as cmds
from ..protocol.commands import (
    DATA_INDEX_MAX,
    HIGH_VOLUME_DATA_INDEX_MAX,
    HIGH_VOLUME_KINDS,
    SERVICE_REQUEST_KINDS,
    Command,
    CommandError,
    Kind,
)
from ..protocol.responses import service_request
from ..protocol.timing import (
    CHAR_TIME,
    NO_BREAK_WINDOW,
    RETRY_AFTER_BREAK,
    RETRY_MAX,
    RETRY_MIN,
    TOLERANCE,
)
from ..protocol.values import continues_split_value, split_values
from ..transcript import (
    COLLISION,
    TOOL,
    Event,
    EventKind,
    decode_7e1,
    encode_7e1,
    text_end,
    to_wire_7e1,
)
from ..view.segments import continues_frame
from . import cut_read, validity
from .contention import HOLD_PREFIX, ApartSoFar, collisions, maybe_note_text
from .hooks import Hooks
from .policy import Policy
from .records import CONTENTION, IDLE, NO_REPLY, OK, TOO_LONG, Attempt, Exchange, Measurement
from .reply_end import Framing, read_rest
from .validity import ends_line

#: After this many holds that reached ``max_hold`` (a DUT that never goes quiet), later holds
#: are bounded by the turnaround: waiting a second before every command of the run would
#: only make a babbling device's run hundreds of seconds longer, never quieter.
OVERRUNS_BEFORE_SHORT = 3


class ToolRecorder:
    """Drives a :class:`Link` as an SDI-12 data recorder and returns records.

    ``address`` is the default sensor address for the conveniences (:meth:`identify`...).
    ``hooks`` takes the decisions a deviating recorder makes differently (:mod:`.hooks`);
    the default ones take the engine's own.
    """

    def __init__(
        self,
        link: Link,
        policy: Policy | None = None,
        *,
        address: str = "0",
        hooks: Hooks | None = None,
    ) -> None:
        self.link = link
        self.policy = policy or Policy()
        self.hooks = hooks if hooks is not None else Hooks()
        self.address = address
        self.last_address: str | None = None  # address of the last command sent
        self.last_break_end = float("-inf")
        # Whether D replies for each address carry a CRC: set by the last accepted
        # measurement reply, used when a D command is sent on its own.
        self._crc_pending: dict[str, bool] = {}
        self.holds = 0  # transmissions held back while the DUT was talking (listen before talk)
        self.hold_overruns = 0  # holds cut short by ``policy.max_hold``
        self.collisions = 0  # tool transmissions that overlapped DUT characters (noted)
        self._scanned = 0  # transcript events already looked at for collisions
        self._collided: set[tuple[float, float]] = set()  # tool events already noted
        self._apart = ApartSoFar()  # the collision scan's shortcut, read on as events come
        self._dut_end = _LastDutChar()  # the end of the DUT's last character, kept up to date
        #: the end of the last reply read whole to its CR LF after which no rule reads on
        #: (:func:`closes_exchange`): no look past the turnaround after it (issue 22, eff11)
        self._closed_reply_end: float | None = None
        #: Addresses whose ``a!`` drew a reply so far (valid or not, not contention): silence
        #: to an ``a!`` probe (a wake-up, a poll at a new address) is evidence only from a
        #: sensor shown to answer ``a!`` at all (:func:`~conformance.preconditions.acknowledges`).
        self.acknowledged: set[str] = set()
        #: The last exchange sent (by :meth:`transact` or :meth:`raw`): a reply that comes
        #: after the next command may be this one's, late (:mod:`..sensor.address_change`).
        self.last_exchange: Exchange | None = None
        #: the last attempt, if its read ended IDLE on a link whose deliveries may lag: the
        #: next try's first characters may be its rest (:mod:`.cut_read`)
        self._cut: cut_read.CutRead | None = None
        #: the policy the framings were made for, and each kind of reply's (:meth:`_framing`)
        self._framings: tuple[Policy | None, dict[tuple[bool, bool], Framing]] = (None, {})

    # -- single commands -------------------------------------------------------------------
    def transact(
        self,
        command: Command | str,
        *,
        binary: bool | None = None,
        force_break: bool = False,
        retries: bool = True,
        expect_reply: bool = True,
        crc: bool | None = None,
    ) -> Exchange:
        """Send ``command`` with the break and retry rules of section 7 and record it all.

        ``binary`` reads the reply as an 8N1 packet; None does so for ``aDBn!`` only.
        ``retries=False`` or ``expect_reply=False`` sends once (observation cases: silence
        may be the point).
        ``crc`` says whether a D reply carries a CRC; None takes it from the last measurement
        this engine started at that address.
        """
        if isinstance(command, str):
            command = cmds.parse_command(command)
        text = command.text()
        if binary is None:
            binary = command.kind is _BINARY_DATA
        if crc is None and command.kind in _DATA_KINDS:
            crc = self._crc_pending.get(command.address)
        wire = encode_7e1(text)
        exchange = Exchange(command, text, [], binary=binary, expect_reply=expect_reply)
        repeat = retries and expect_reply
        sequences = self.policy.sequences if repeat else 1
        per_sequence = self.policy.retries_per_sequence if repeat else 0
        for sequence in range(sequences):
            # R-7.2-04: every repeated sequence starts again with a break.
            brk: bool | None = True if (force_break or sequence > 0) else None
            for retry in range(per_sequence + 1):
                if retry:
                    self.link.wait_until(self._retry_time(exchange, sequence, per_sequence))
                attempt = self._attempt(
                    wire,
                    text[0],
                    command,
                    brk=brk if retry == 0 else None,
                    binary=binary,
                    crc=crc,
                )
                attempt.sequence, attempt.retry = sequence, retry
                exchange.attempts.append(attempt)
                if self._cut is not None:  # this attempt's read was cut (cut_read)
                    self._cut.exchange = exchange
                if attempt.ok:
                    self._note_accepted(command)
                    self.last_exchange = exchange
                    return exchange
        self.last_exchange = exchange
        return exchange

    def raw(
        self,
        text: str | bytes,
        *,
        break_first: bool | None = None,
        gap: float = 0.0,
        parity: bool = True,
        binary: bool = False,
        marking: float | None = None,
        collide: bool = False,
    ) -> Exchange:
        """Send arbitrary characters once (malformed commands, foreign addresses, partial
        commands with a ``gap`` of marking between characters) and record what came back.

        ``parity`` adds even parity to each 7-bit character; False sends the bytes as given
        (wrong parity on purpose). ``break_first`` None applies the usual break rules to the
        first character as address; True/False forces or suppresses the break. ``marking``
        replaces ``policy.post_break_marking`` after that break (a probe sent the way the
        sensor was shown to hear, :meth:`SensorSession.hearing_marking`). ``collide``
        transmits without listening first (:meth:`clear_to_send`): only for a probe that means
        to talk into the DUT.
        """
        data = text.encode("latin-1") if isinstance(text, str) else text
        wire = bytes(to_wire_7e1(b) if parity else b for b in data)
        shown = data.decode("latin-1")
        try:
            command: Command | None = cmds.parse_command(shown)
        except CommandError:
            command = None
        address = chr(data[0] & 0x7F) if data else ""
        attempt = self._attempt(
            wire,
            address,
            command,
            brk=break_first,
            binary=binary,
            gap=gap,
            marking=marking,
            collide=collide,
        )
        exchange = Exchange(command, shown, [attempt], binary=binary, expect_reply=False)
        if self._cut is not None:  # this attempt's read was cut (cut_read)
            self._cut.exchange = exchange
        self.last_exchange = exchange
        return exchange

    def send_break(self, marking: float | None = None, *, collide: bool = False) -> Event:
        """A break of ``policy.break_duration`` then ``policy.post_break_marking`` (or
        ``marking``) of marking (R-7.0-02, R-7.0-06), once the DUT has released the line
        (R-7.0-11) and is not talking (:meth:`clear_to_send`; ``collide`` skips that)."""
        self.clear_to_send(collide=collide)
        return self._break(marking)

    def clear_to_send(self, *, collide: bool = False) -> float:
        """Listen before talk: wait until the tool may drive the line, and return when.

        A real recorder's UART sees the DUT's start bits; this one sees the DUT's characters
        as the link delivers them, up to ``timing_uncertainty`` late, so the line must have
        been quiet for the turnaround and then that look more (:meth:`look_before_transmit`)
        before it transmits: what arrives by then is taken in (not after the tool's own
        break: the line has been the tool's since, and a timed probe's marking must not grow).
        While the DUT's last character ended less than ``policy.turnaround`` (R-7.0-11;
        longer than any gap inside a reply) and the look ago, the transmission is held. The
        look is counted from the end of the turnaround, not from whenever the engine came to
        ask: after a wait that already listened to a quiet line for that long (a read to its
        deadline, a case's listening, a retry's spacing) it is done, and adding it again only
        made every such transmission ``timing_uncertainty`` later (issue 22). At the moment
        of transmitting the tool knows exactly what it knew before, what arrived by then,
        and holds on more of it: a character seen less than turnaround and look ago.
        A DUT that keeps talking is waited out for at most ``policy.max_hold``; then the tool
        transmits anyway, with a NOTE. Nothing is read off the link here: what the DUT sent
        stays queued for whoever reads next (the attempt's stray characters, or a case
        waiting for a service request). ``collide``: transmit now, without listening or the
        turnaround (a probe that means to talk into the DUT). Collisions that happened anyway
        are noted (:meth:`note_collisions`)."""
        self.note_collisions()
        if collide:
            return self.link.now()
        settled = settled_at(self.link.transcript.events)
        if settled is not None and settled > self.link.now():
            # what a stall of the tool's host just held back is still arriving: the reply
            # its read cut may be going on (truth30, host_stall.AFTER)
            self.link.wait_until(settled)
        look = self.look_before_transmit()
        self.link.wait_until(self._earliest_transmit(look))
        began = self.link.now()
        uncertainty = self.link.info.timing_uncertainty
        held = False
        while True:
            clear = self._earliest_transmit(look)
            now = self.link.now()
            if clear <= now:
                break
            # a DUT that never went quiet in OVERRUNS_BEFORE_SHORT holds is not waited out
            # for the whole bound again: each later hold lasts the turnaround only
            bound = self.policy.max_hold
            if self.hold_overruns >= OVERRUNS_BEFORE_SHORT:
                bound = min(bound, self.policy.turnaround)
            if now - began >= bound:
                self.hold_overruns += 1
                self.link.transcript.note(
                    now,
                    f"{HOLD_PREFIX}the DUT was still transmitting after {(now - began) * 1e3:.0f}"
                    f" ms of holding (bound {bound * 1e3:.0f} ms); the tool "
                    "transmits into it",
                )
                break
            held = True
            self.link.wait_until(min(clear, began + bound))
            look = look_past_turnaround(uncertainty, self.policy.turnaround)
        self.holds += held
        return self.link.now()

    def look_before_transmit(self) -> float:
        """How long past the turnaround after the DUT's last character :meth:`clear_to_send`
        listens before it transmits (s): what the turnaround leaves of a back-to-back
        character's frame and the link's timing uncertainty (:func:`look_past_turnaround`),
        or nothing right after the tool's own break or after a reply that closed its exchange
        at its CR LF, where no rule reads what follows (:func:`closes_exchange`; a character
        the DUT sent since brings the look back). It ends that long after the turnaround,
        so a case that aims a transmission at a moment later than that need not start its
        wait any earlier (:meth:`SensorSession.mark_until`)."""
        if _own_break_last(self.link):
            return 0.0
        closed = self._closed_reply_end
        if closed is not None and self._dut_end.after(self.link.transcript.events) == closed:
            return 0.0
        return look_past_turnaround(self.link.info.timing_uncertainty, self.policy.turnaround)

    def note_collisions(self) -> int:
        """Add a collision NOTE for each tool transmission that overlapped DUT characters
        since the last look (:mod:`~conformance.tool_recorder.contention`); returns how many
        transmissions collided so far."""
        events = self.link.transcript.events
        first = max(0, self._scanned - _COLLISION_LOOKBACK)
        if self._apart.holds(events, first):  # nothing met: no collision to note
            self._scanned = len(events)
            return self.collisions
        window = events[first:]
        self._scanned = len(events)
        for collision in collisions(window):
            spans = {(e.start, e.end) for e in collision.tool}
            if spans & self._collided:
                continue
            self._collided |= spans
            self.collisions += 1
            self.link.transcript.note(collision.start, collision.note_text())
        return self.collisions

    def _note_maybe_collided(
        self, break_event: Event | None, sent: list[Event], collided: list[Event]
    ) -> None:
        """A NOTE for a transmission that met DUT characters the stamps do not show it
        overlapped by more than their uncertainty (no collision NOTE was made for it): over
        RFC 2217 with a stray '#' 2 ms after a reply's LF, the next command began 0.1..1.2 ms
        before the '#' ended at ±5 ms, 106 of 267 times, and left no trace in the report."""
        tool = ([break_event] if break_event is not None else []) + sent
        uncertainty = self.link.info.timing_uncertainty
        if uncertainty <= 0 or not tool or any((e.start, e.end) in self._collided for e in tool):
            return  # exact stamps say whether they overlapped (a sim bus interleaves them)
        met = [e for e in collided if e.end + max(uncertainty, e.uncertainty) > tool[0].start]
        if met:  # (characters that ended before it began, by the stamps and more: no meeting)
            self.link.transcript.note(tool[0].start, maybe_note_text(tool, met, uncertainty))

    def _break(self, marking: float | None) -> Event:
        event = self.link.send_break(self.policy.break_duration)
        self.last_break_end = event.end
        self.link.wait(self.policy.post_break_marking if marking is None else marking)
        return event

    # -- conveniences ----------------------------------------------------------------------
    def acknowledge(self, address: str | None = None) -> Exchange:
        return self.transact(cmds.acknowledge(address or self.address))

    def identify(self, address: str | None = None) -> Exchange:
        return self.transact(cmds.identify(address or self.address))

    def query_address(self) -> Exchange:
        return self.transact(cmds.query_address())

    def change_address(self, new: str, address: str | None = None) -> Exchange:
        exchange = self.transact(cmds.change_address(address or self.address, new))
        if exchange.ok and (address or self.address) == self.address:
            self.address = new
        return exchange

    # -- measurements ----------------------------------------------------------------------
    def measure(self, command: Command, *, collect: bool = True, wait: str = "auto") -> Measurement:
        """Start a measurement, wait for its data, and (``collect``) read D0.. / DB0...

        ``wait``: "auto" follows the standard (service request for M/V, ttt for C/HA/HB);
        "ttt" waits the full ttt even for M/V (ignoring a service request but recording it);
        "none" does not wait at all (probing early D commands).
        """
        if not command.starts_measurement:
            raise ValueError(f"{command} does not start a measurement")
        if wait not in ("auto", "ttt", "none"):
            raise ValueError(f"unknown wait mode {wait!r}")
        start = self.transact(command)
        m = Measurement(command, start)
        parsed = validity.parse_start_reply(start.reply_text, validity.count_digits(command))
        if parsed is None or not (start.ok or self.policy.salvage):
            return m
        if not start.ok:
            self._note_accepted(command)  # salvaged: D replies follow this measurement
        m.ttt, m.count = parsed
        m.reply_end = start.reply_events[-1].end
        use_sr = wait == "auto" and _raises_sr(command)
        if m.ttt > 0 and wait != "none":
            self._wait_for_data(m, service_request=use_sr)
        if collect:
            # D0 goes without a forced break only right after an answered service request
            # (R-7.1-01), for ttt = 0, or when probing early; after ttt it gets a break.
            waited_out = m.ttt > 0 and wait != "none"
            answered_sr = use_sr and m.service_request_end is not None
            self.collect(m, force_break=waited_out and not answered_sr)
        return m

    def collect(
        self, m: Measurement, *, force_break: bool | None = None, max_index: int | None = None
    ) -> Measurement:
        """Read D0, D1, ... (DB0, DB1, ... after HB) until ``m.count`` values are in.

        Stops on an invalid reply (after retries), an empty reply (aborted measurement,
        R-4.4.8-05), the empty binary packet (R-5.2-08) or the last index the command family
        allows (D9, or D999 after HA/HB without leading zeros, R-5.1-04). Continues after the
        last index already collected, so it can be called again. ``force_break`` for the first
        D command defaults to "ttt ran out without a service request" (R-4.4.5-05).
        """
        if m.count is None:
            return m
        address = m.command.address
        # D0..D9, or D0..D999 / DB0..DB999 after HA/HB (R-5.1-04)
        high = m.command.kind in HIGH_VOLUME_KINDS
        limit = HIGH_VOLUME_DATA_INDEX_MAX if high else DATA_INDEX_MAX
        if max_index is not None:
            limit = min(limit, max_index)
        crc = m.command.returns_crc
        if force_break is None:
            force_break = bool(m.ttt) and m.service_request_end is None
        index = len(m.data)
        probed_past_empty = False
        while index <= limit and m.value_count < m.count:
            if m.binary:
                exchange = self.transact(
                    cmds.binary_data(address, index), binary=True, force_break=force_break
                )
            else:
                exchange = self.transact(
                    cmds.data(address, index), force_break=force_break, crc=crc
                )
            force_break = False
            m.data.append(exchange)
            usable = exchange.ok or (self.policy.salvage and exchange.answered)
            if not usable:
                break
            if not take_values(m, exchange, crc) and not reads_on(m, self.policy):
                # An empty reply ends collection (R-4.4.8-05). An observer looks one index
                # further, once, so a sensor whose groups start late leaves evidence.
                if (
                    not self.policy.salvage
                    or probed_past_empty
                    or m.binary
                    or m.aborted_by is not None
                ):
                    break
                probed_past_empty = True
            index += 1
        return m

    def abort(self, m: Measurement, command: Command | str | None = None) -> Event | Exchange:
        """Abort ``m`` on purpose: with a break (R-4.4.5.1-01) or with ``command`` sent to the
        sensor (a concurrent abort, R-4.4.7.1-01). Recorded in ``m.aborted_by``."""
        if command is None:
            m.aborted_by = "break"
            return self.send_break()
        exchange = self.transact(command)
        m.aborted_by = exchange.text
        return exchange

    # -- internals -------------------------------------------------------------------------
    def _note_accepted(self, command: Command) -> None:
        if command.starts_measurement:
            self._crc_pending[command.address] = command.returns_crc

    def _wait_for_data(self, m: Measurement, *, service_request: bool) -> None:
        """Wait for ``m``'s data as the hooks say (:meth:`Hooks.wait_for_data`)."""
        self.hooks.wait_for_data(
            self, m, service_request, lambda: self._usual_wait_for_data(m, service_request)
        )

    def _usual_wait_for_data(self, m: Measurement, service_request: bool) -> None:
        """Wait out ttt, recording every DUT character; with ``service_request`` stop at the
        first ``a<CR><LF>`` (R-4.4.5-04, R-4.4.6). Keeps listening ``late_sr_grace`` past ttt
        so a late service request is evidence, not a miss."""
        assert m.reply_end is not None and m.ttt is not None
        ready = m.reply_end + m.ttt
        if not service_request:
            m.waited_events.extend(self.link.receive(ready + self.policy.ttt_margin))
            m.service_request_end = _service_request_end(m.waited_events, m.command.address)
            return
        deadline = ready + max(self.policy.late_sr_grace, self.policy.ttt_margin)
        while self.link.now() < deadline:
            got = self.link.receive(deadline, until=validity.ends_line)
            m.waited_events.extend(got)
            end = _service_request_end(m.waited_events, m.command.address)
            if end is not None:
                m.service_request_end = end
                return
            if not got:
                return

    def _earliest_transmit(self, look: float = 0.0) -> float:
        """Now, or later if the DUT may still hold the line after its last character (and
        ``look`` past that, for characters the link delivers late). Without a look (a reply
        that closed its exchange, or the tool's own break last) the turnaround counts from
        the latest the character can have ended on the wire (:meth:`Link.received_by`),
        which a real link's stamp may lie past; with one, from the stamp, as the look's
        figure was drawn from the stamps."""
        last_dut = self._dut_end.after(self.link.transcript.events)
        if not look:
            last_dut = self.link.received_by(last_dut)
        return max(self.link.now(), last_dut + self.policy.turnaround + look)

    def _needs_break(self, address: str, at: float) -> bool:
        """Whether the break rules put a break in front, as the hooks say."""
        return self.hooks.needs_break(
            self, address, at, lambda: self._usual_needs_break(address, at)
        )

    def _usual_needs_break(self, address: str, at: float) -> bool:
        """R-7.0-17 / R-7.1-01: break for a new address or after > 87 ms of marking; and
        where the link noted a stall of the tool's own host after the line's last activity
        (:func:`~conformance.links.host_stall.noted_since_activity`), whose stamp may then be
        the late burst's: a service request the stall held back reads as just ended, and
        ``aD0!`` sent "within 87 ms" of it without a break may find the sensor asleep for
        100 ms already, its silence then taken for the sensor's (truth30)."""
        if self.last_address is None or address != self.last_address:
            return True
        window = NO_BREAK_WINDOW - self.policy.window_margin - self.link.info.timing_uncertainty
        if at - self.link.last_activity() > window:
            return True
        self.link.reader_caught_up()
        return noted_since_activity(self.link.transcript.events)

    def _transmit(
        self,
        wire: bytes,
        address: str,
        brk: bool | None,
        gap: float,
        marking: float | None,
        collide: bool,
    ) -> tuple[Event | None, list[Event], list[Event]]:
        """Listen before talk, then the break (if due) and the command. Also returns the DUT
        characters that came before it (a service request the hold waited out): queued
        chatter, never this command's reply."""
        at = self.clear_to_send(collide=collide)
        stray = self.link.receive(at)
        break_event = None
        if brk or (brk is None and self._needs_break(address, at)):
            # socket://: the link noted it; the command goes alone
            with contextlib.suppress(BreakUnsupported):
                break_event = self._break(marking)
        # gap 0: back to back, R-7.0-13
        events = self.link.write(wire, self.hooks.command_gap(self, gap))
        self.last_address = address
        return break_event, events, stray

    def _attempt(
        self,
        wire: bytes,
        address: str,
        command: Command | None,
        *,
        brk: bool | None,
        binary: bool,
        crc: bool | None = None,
        gap: float = 0.0,
        marking: float | None = None,
        collide: bool = False,
    ) -> Attempt:
        """One transmission and its reply, as the hooks let it go (:meth:`Hooks.attempt`)."""

        proceeded = False

        def proceed() -> Attempt:
            nonlocal proceeded
            proceeded = True
            return self._usual_attempt(
                wire, address, command, brk, binary, crc, gap, marking, collide
            )

        attempt = self.hooks.attempt(self, wire, address, command, proceed)
        if not proceeded:  # a hook's own attempt: no reply known to have closed it
            self._closed_reply_end = None
        return attempt

    def _usual_attempt(
        self,
        wire: bytes,
        address: str,
        command: Command | None,
        brk: bool | None,
        binary: bool,
        crc: bool | None,
        gap: float,
        marking: float | None,
        collide: bool,
    ) -> Attempt:
        """Listen before talk, send, then read and judge the reply."""
        break_event, sent, stray = self._transmit(wire, address, brk, gap, marking, collide)
        self._closed_reply_end = None
        command_end = sent[-1].end if sent else self.link.now()
        framing = self._framing(
            binary, not binary and (command is None or command.kind is _EXTENDED)
        )
        reply, state, collided = self._listen(command_end, framing)
        mending, self._cut = self._cut, None
        if mending is not None:  # the rest of a reply a stall cut comes before this one
            stray = mending.mend(stray)
            if not stray and collided:
                first_sent = break_event or (sent[0] if sent else None)
                collided = mending.mend_met(collided, first_sent, read_on=not reply)
        text: str | None = None
        if collided:
            self.note_collisions()
            self._note_maybe_collided(break_event, sent, collided)
        if collided:  # the DUT talked over the command: it may not have heard it whole
            state = f"{CONTENTION} ({len(collided)} characters during the command)"
        elif state is None:
            # the reply's text, decoded once: the check reads it, and the attempt carries it
            # to every later reader (Attempt.reply_text)
            text = None if framing.binary else decode_7e1(reply)
            state = self._judge_reply(reply, command, address, command_end, framing, crc, text)
        if (
            reply
            and not collided
            and command is not None
            and command.kind is _ACKNOWLEDGE
            and not carries_values(decode_7e1(reply) if text is None else text)
        ):
            self.acknowledged.add(address)
        if not collided and not framing.is_text(reply) and closes_exchange(command, reply):
            self._closed_reply_end = reply[-1].end
        attempt = Attempt(
            break_event, sent, reply, state, self.link.now(), stray_events=stray + collided
        )
        if text is not None:
            attempt.knows_reply_text(text)
        if state == IDLE:
            self._cut = cut_read.cut(
                attempt,
                framing,
                self.link,
                judge=lambda chars, text: self._judge_reply(
                    chars, command, address, command_end, framing, crc, text
                ),
            )
        return attempt

    def _framing(self, binary: bool, multiline: bool) -> Framing:
        """:func:`framing_for` this engine's policy, made once per policy object and kind
        of reply rather than per attempt (a frozen dataclass's ``__init__`` sets each field
        by name; a fault-matrix row makes some 3,000 attempts). Policy and Framing are
        frozen; a case that gives the engine another policy gets framings of its own."""
        policy, made = self._framings
        if policy is not self.policy:
            policy, made = self.policy, {}
            self._framings = (policy, made)
        key = (binary, multiline)
        framing = made.get(key)
        if framing is None:
            framing = made[key] = framing_for(policy, binary, multiline)
        return framing

    def _listen(
        self, command_end: float, framing: Framing
    ) -> tuple[list[Event], str | None, list[Event]]:
        """Read one reply: the first start bit within ``first_char_timeout``, then until the
        framing says it is complete, the line marks for the framing's window, or the DUT has
        sent too much. Returns the characters, NO_REPLY/IDLE/TOO_LONG (or None when the
        reply finished and needs checking), and the characters that began before the command
        ended: they collided with it (a late reply to an earlier transmission, say) and are
        never this command's answer. Every read has a deadline."""
        deadline = command_end + self.policy.first_char_timeout
        one_line = not (framing.binary or framing.multiline)
        line_at_once = getattr(type(self.link), "reads_line_at_once", False)
        if one_line and line_at_once and self.link.now() >= command_end:
            # a sim link reads a one-line reply in one pass (SimLink.receive_line): what
            # began after the clock began after the command, so nothing collided with it
            line = getattr(self.link, "receive_line", None)
            got = None if line is None else line(deadline, framing.deadline, framing.max_chars,
                                                 framing.idle)  # fmt: skip
            if got is not None:
                return got, self._line_state(got, framing), []
        collided: list[Event] = []
        first = self.link.receive(deadline, until=lambda got: True)
        slack = self.link.info.timing_uncertainty
        while first and (
            first[0].start < command_end
            # a character the bus held behind the command it wanted the line during (a
            # harness's frame planned inside the tool's: marked COLLISION): it met the
            # command too, whatever its stamp (view.segments._collided_each's rule). Taken as
            # the reply, a values line of the aR0! before, due while its retry was on the
            # line, PASSed R-4.4.8.1-01 for 0R0! (outside34's ENG20009 Due sketch, truth37)
            or first[0].text == COLLISION
            # its tail, up to its LF (the view's rule, so the live read and the judges agree)
            or (collided and continues_frame(collided[-1], first[0], command_end, slack))
        ):
            collided += first
            first = self.link.receive(deadline, until=lambda got: True)
        if not first:
            return [], NO_REPLY, collided
        deadline = framing.deadline(first[0])
        chars = first
        if line_at_once and one_line:
            reply, state = self._rest_of_line(chars, deadline, framing)
            return reply, state, collided
        chars = read_rest(self.link, framing, chars, deadline)
        if framing.finished(chars):
            return chars, None, collided
        if len(chars) >= framing.limit(chars):
            return chars, TOO_LONG, collided
        if framing.at_line_end(chars):
            return chars, None, collided  # no next line within 150 ms: complete
        return chars, IDLE, collided

    def _rest_of_line(
        self, chars: list[Event], deadline: float, framing: Framing
    ) -> tuple[list[Event], str | None]:
        """:meth:`_listen`'s loop for a one-line 7E1 reply on a link that
        :attr:`~conformance.links.base.Link.reads_line_at_once`: one read to the CR LF, the
        reply's limit, the marking of ``framing.idle`` after a character or ``deadline``,
        what the loop's reads of one idle window each came to (each began a window after
        the last character so far, and its idle rule after each of its own: a character is
        taken exactly when it starts within ``idle`` of the one before and before
        ``deadline``, however the reads are cut). Returns the characters and the reason
        (None: complete, to be checked)."""
        limit = framing.max_chars
        if not (ends_line(chars) or len(chars) >= limit):
            chars = chars + self.link.receive(
                deadline, until=LineEnd(chars, limit), idle=framing.idle
            )
        return chars, self._line_state(chars, framing)

    @staticmethod
    def _line_state(chars: list[Event], framing: Framing) -> str | None:
        """Why a one-line 7E1 reply read to its end stopped: NO_REPLY (no character),
        None (its CR LF: complete, to be checked), TOO_LONG (the reply's limit) or IDLE."""
        if not chars:
            return NO_REPLY
        if ends_line(chars):
            return None
        return TOO_LONG if len(chars) >= framing.max_chars else IDLE

    def _judge_reply(
        self,
        reply: list[Event],
        command: Command | None,
        address: str,
        command_end: float,
        framing: Framing,
        crc: bool | None,
        text: str | None = None,
    ) -> str:
        """OK, or why the finished ``reply`` is invalid (:mod:`.validity`); ``text``: its
        ``decode_7e1`` where the caller has it."""
        if framing.binary:
            why = validity.check_packet(reply, address=address, command_end=command_end)
        else:
            gap_limit = CHAR_TIME + TOLERANCE + self.link.info.timing_uncertainty
            why = validity.check_ascii(
                command,
                reply,
                address=address,
                command_end=command_end,
                gap_limit=gap_limit,
                crc_expected=crc,
                multiline=framing.is_text(reply),
                text=text,
            )
        return OK if why is None else f"invalid: {why}"

    def _retry_time(self, exchange: Exchange, sequence: int, per_sequence: int) -> float:
        """When the next retry starts, as the hooks say (:meth:`Hooks.retry_time`)."""
        return self.hooks.retry_time(
            self,
            exchange,
            sequence,
            per_sequence,
            lambda: self._usual_retry_time(exchange, sequence, per_sequence),
        )

    def _usual_retry_time(self, exchange: Exchange, sequence: int, per_sequence: int) -> float:
        """When the next retry (no break) starts, per R-7.2-02/03/06.

        ``retry_gap`` after the end of the invalid reply (it must have finished) or of the
        first-character timeout; never sooner than 16.67 ms after the command's last stop bit;
        for no reply never later than 87 ms after it. The last retry of a sequence is pushed
        past 100 ms after the break if no earlier retry was, so a sensor that needs its full
        100 ms to wake still gets one try. With fewer than two retries that can exceed the 87
        ms window; the break rule then puts a break in front (R-7.0-17) rather than break it.
        """
        p = self.policy
        prev = exchange.last
        assert prev.command_end is not None
        base = prev.reply_events[-1].end if prev.reply_events else _timed_out(prev, p)
        time = max(prev.command_end + RETRY_MIN + p.window_margin, base + p.retry_gap)
        if not prev.reply_events:
            time = min(time, prev.command_end + RETRY_MAX - p.window_margin)
        retries = [a for a in exchange.attempts if a.sequence == sequence and a.retry > 0]
        is_last = len(retries) + 1 == per_sequence
        wake = self.last_break_end + RETRY_AFTER_BREAK + p.window_margin
        if is_last and not any(a.command_events[0].start > wake for a in retries):
            time = max(time, wake)
        return max(time, self.link.now())


#: how far past its first-character deadline a silent try's read may end and still count
#: from its own end (float rounding, a virtual clock's exact stop)
READ_OVERSHOOT_SLACK = 1e-6


def _timed_out(prev: Attempt, p: Policy) -> float:
    """Where a try that drew no reply stopped listening, for the retry gap to count from:
    its first-character deadline, not the end of a read that a real link let run past it.
    Over RFC 2217 behind a jittery echoing link on a loaded host a silent read ended 15-25
    ms past its 30 ms deadline; counted from there, each retry came back more than 87 ms
    after the command, the break rule put a break in front of every one, and a sensor that
    needs up to 100 ms after a break (R-7.0-07) heard no try at all (truth23: slow-wake's
    '0IM_000! got no reply', 9 tries, each 9-20 ms after a break of its own). A try whose read
    went on through characters that met it (``stray_events``: a late reply colliding with
    it) keeps its read's end: the retry waits for them."""
    assert prev.command_end is not None
    due = prev.command_end + p.first_char_timeout
    if prev.stray_events or prev.end - due <= READ_OVERSHOOT_SLACK:
        return prev.end  # it read on through characters that met the command: after them
    return due


def _raises_sr(command: Command) -> bool:
    """M family and V answer with a service request (R-4.4.6-02, decision A5)."""
    return command.kind in SERVICE_REQUEST_KINDS


def _service_request_end(events: list[Event], address: str) -> float | None:
    """End of the first ``a<CR><LF>`` with good parity among ``events`` (R-4.4.6-01)."""
    return text_end(events, service_request(address))


#: Events before the last look that a collision scan takes again, so a transmission whose
#: DUT characters arrived after the look is still seen whole.
_COLLISION_LOOKBACK = 64


def look_past_turnaround(uncertainty: float, turnaround: float) -> float:
    """The look after the turnaround (s): a DUT that goes on talking back to back after its
    last character (its CR LF) starts the next one as that one ends, so the link has shown
    it ``CHAR_TIME`` (its frame) plus at most ``uncertainty`` (the link's lateness) after the
    last one's stamp. The turnaround already listened that long but for the rest, so the look
    is the rest, not the whole uncertainty again: 4.33 ms behind RFC 2217 (5 ms), where the
    look used to run 5 ms past the turnaround and so waited for a character that started up
    to 0.67 ms after the CR LF as well (issue 22, eff10: 0.67 ms of each of about 680
    turnarounds a real run). On the sim (no uncertainty) the turnaround covers the frame and
    nothing is added, as before."""
    return max(0.0, CHAR_TIME + uncertainty - turnaround)


#: Commands whose one-line reply ends the exchange at its CR LF: nothing the standard lets
#: the sensor send may follow it at once. Left out: measurements and aIM!-style commands
#: (their ``atttn`` may be followed by a service request, at once where ttt is 000: R-4.4.6-03,
#: R-6.1-03), extended and unparsed commands (a reply may run over several lines), binary.
CLOSED_BY_LINE_END = frozenset(
    {
        Kind.ACKNOWLEDGE,
        Kind.QUERY_ADDRESS,
        Kind.IDENTIFY,
        Kind.CHANGE_ADDRESS,
        Kind.DATA,
        Kind.CONTINUOUS,
        Kind.METADATA,
    }
)


def framing_for(policy: Policy, binary: bool, multiline: bool) -> Framing:
    """How the tool recorder frames a reply under ``policy`` (binary: an 8N1 packet;
    multiline: a reply that may be a multi-line text)."""
    p = policy
    return Framing(
        idle=p.reply_idle,
        max_chars=p.max_binary_bytes if binary else p.max_reply_chars,
        binary=binary,
        multiline=multiline,
        max_text_chars=p.max_text_chars,
        line_wait=p.line_wait,
    )


def closes_exchange(command: Command | None, reply: list[Event]) -> bool:
    """Whether ``reply``, read to its CR LF, leaves nothing a rule reads on the line after it,
    so the tool may transmit once the turnaround is over without the look for a character
    sent back to back after the LF (:meth:`ToolRecorder.look_before_transmit`). A compliant
    sensor has released the line 7.5 ms after its LF (R-7.0-11) and the turnaround is 9 ms
    after the LF's stamp, which is never earlier than its end on the wire: the tool
    transmits inside the standard, and what a faulty sensor still sends is recorded all
    the same (a collision is noted). Where a rule does read what follows at once (a
    service request after ``atttn``) the look stays. Issue 22, eff11: about 600 of a real
    run's 680 turnarounds behind RFC 2217, 4.33 ms each."""
    return (
        command is not None
        and command.kind in CLOSED_BY_LINE_END
        and validity.ends_line(reply)
        # every one a character (``kind is CHAR``), read in C rather than a generator
        # step per character of every reply
        and all(map(is_, map(_KIND, reply), repeat(_CHAR)))
    )


_KIND = attrgetter("kind")
#: the kinds every attempt asks about, as module constants: a member read off the enum goes
#: through its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us
#: a look, some ten looks an attempt)
_CHAR, _NOTE, _BREAK = EventKind.CHAR, EventKind.NOTE, EventKind.BREAK
_BINARY_DATA, _EXTENDED, _ACKNOWLEDGE = Kind.BINARY_DATA, Kind.EXTENDED, Kind.ACKNOWLEDGE
_DATA_KINDS = (Kind.DATA, Kind.BINARY_DATA)


def _own_break_last(link: Link) -> bool:
    """Whether the last thing on the wire is the tool's own break (its marking follows)."""
    for event in reversed(link.transcript.events):
        if event.kind is not _NOTE:
            return event.kind is _BREAK and event.origin == TOOL
    return False


class _LastDutChar:
    """The end of the last DUT character a transcript holds, read on from where the previous
    look stopped (a transcript only grows): scanning it backwards before every transmission
    cost a harness run about 0.5 s, where the harness's notes and the tool's own characters
    stand between the DUT's replies."""

    def __init__(self) -> None:
        self.seen = 0
        self.end = float("-inf")
        self._last: Event | None = None  # the event at ``seen - 1`` when last looked

    def after(self, events: list[Event]) -> float:
        """The end of the last DUT character in ``events`` (-inf: none yet)."""
        if self.seen and (len(events) < self.seen or events[self.seen - 1] is not self._last):
            self.seen, self.end = 0, float("-inf")  # not only appended to: read it all again
        char = _CHAR
        # the last of the new events that is a DUT character, looked for from the end (what
        # the forward pass kept in the end: each such end overwrote the one before); a reply
        # read ends in its own characters, so the look stops at once
        for k in range(len(events) - 1, self.seen - 1, -1):
            event = events[k]
            if event.kind is char and event.origin != TOOL:
                self.end = event.end
                break
        self.seen = len(events)
        self._last = events[-1] if events else None
        return self.end


def reads_on(m: Measurement, policy: Policy) -> bool:
    """After a DB packet without values: an observer reads on past an unreadable one as it
    does past an invalid ASCII D reply (:func:`validity.reads_past_packet`). The view
    rebuilds records with the same rule."""
    return (
        m.binary
        and policy.salvage
        and m.aborted_by is None
        and validity.reads_past_packet(m.packets, m.count or 0)
    )


def carries_values(text: str) -> bool:
    """Whether a reply to ``a!`` carries signed values after its address (``0+1013.25``):
    no acknowledgement, valid or not, does; a sensor's data line sent late, or a second line
    of the command before's reply, does. Such a reply is no sign the sensor answers ``a!``
    (:attr:`ToolRecorder.acknowledged`): an ENG20009 Due sketch (docs/kit.md, thirty-fourth
    round) that answers no ``a!`` sent its ``aR2!``'s second line 3 ms after an ``a!``, and
    the silence to ``a!`` at a new address then FAILed R-4.4.4-03 and stopped the run."""
    first = text.split("\r", 1)[0][1:]
    return any(first[i] in "+-" and first[i + 1 : i + 2].isdigit() for i in range(len(first)))


def take_values(m: Measurement, exchange: Exchange, crc: bool) -> bool:
    """Add an accepted D/DB reply's values to ``m``; False if it held none (stop). The view
    rebuilds records with the same rule (:mod:`conformance.view.rebuilt_records`)."""
    if m.binary:
        packet = exchange.reply_bytes
        m.packets.append(packet)
        count = validity.packet_value_count(packet)
        m.binary_value_count += count
        return count > 0
    text = validity.data_values_text(exchange.reply_text, crc)
    if not exchange.judged.ok:  # salvaged: only what reads as values (no stray CRC, spaces)
        text = validity.salvaged_values_text(text)
    values = split_values(text)
    held = bool(values)
    if m.values and continues_split_value(values):
        # the rest of a value the reply before cut in two (R-4.4.8.3-01's deviation): one
        # value, not two, or collection stops a value early and the count rule reads the
        # fragments as one value too many (split-value + values-over-35, seed 4065)
        m.values[-1] += values.pop(0)
    m.values.extend(values)
    return held
