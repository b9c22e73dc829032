"""What the sensor's data buffer is known to hold, from what the tool last sent it.

A case that must tell kept data from cleared data (an aborted measurement whose D replies
should be empty) needs values in the buffer before it starts: a sensor that wrongly keeps the
previous data looks conforming when the previous data were empty. What the buffer holds when a
case starts was left by whichever case ran before it, so such a case asks for a filled buffer
explicitly; this watch lets the session say "already filled" without sending anything.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Iterable
from typing import Any

from ..judges.late_before import late_among
from ..links import host_stall
from ..links.base import Link
from ..links.host_stall import Stall
from ..protocol.commands import Command, Kind
from ..protocol.framing import LF
from ..protocol.responses import holds_values
from ..protocol.timing import CHAR_TIME
from ..tool_recorder import stalled_reads
from ..tool_recorder.engine import ToolRecorder
from ..tool_recorder.hooks import Engine, Hooks
from ..tool_recorder.policy import Policy
from ..tool_recorder.records import CONTENTION, Attempt, Exchange, Measurement
from ..transcript import SEVEN_BITS
from .late_watch import LATE_START_LISTEN, LateStartWatch

#: the kinds every attempt is asked about, as module constants: a member read off the enum goes
#: through its metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_DATA, _EXTENDED = Kind.DATA, Kind.EXTENDED


class BufferWatchHooks(Hooks):
    """Engine hooks that change nothing and note, per address, the last command sent and the
    characters of its reply (``last_sent``), and how late a reply was seen to start
    (``late``, :class:`~.late_watch.LateStartWatch`)."""

    def __init__(self) -> None:
        self.last_sent: dict[str, tuple[Command | None, str]] = {}
        self.late = LateStartWatch()  # how late a reply was seen to start (one-shot probes)

    def attempt(
        self,
        master: Engine,
        wire: bytes,
        address: str,
        command: Command | None,
        proceed: Callable[[], Attempt],
    ) -> Attempt:
        """The engine's attempt, noted."""
        attempt = proceed()
        reply = attempt.reply_text  # decoded once, by the engine (Attempt.reply_text)
        self.last_sent[address] = (command, reply)
        self.late.note(attempt, wire.translate(SEVEN_BITS).decode("latin-1"))
        return attempt


class WatchedToolRecorder(ToolRecorder):
    """The tool recorder, noting per address the last command sent and its reply."""

    def __init__(self, link: Link, policy: Policy | None = None, *, address: str = "0") -> None:
        self.watch = BufferWatchHooks()
        super().__init__(link, policy, address=address, hooks=self.watch)
        self.last_sent = self.watch.last_sent
        #: the last :meth:`stalls_since` asked: (transcript's list, first, length) and what
        #: it found
        self._stalls_read: tuple[tuple[int, int, int], list[Stall]] = ((0, -1, -1), [])

    def transact(self, command: Command | str, **kw: Any) -> Exchange:
        """The engine's exchange, linked to the one before it where that may have answered
        late (:meth:`_link_late_before`), its reads marked where the host stalled over them
        (:meth:`mark_stalls`); measurements' starts and D reads come here too."""
        before, seen = self.last_exchange, self.watch.late.start is not None
        first = len(self.link.transcript.events)
        ex = self._hear_late_reply(super().transact(command, **kw))
        self.mark_stalls([ex], first)
        return self._link_late_before(before, ex, seen)

    def raw(self, text: str | bytes, **kw: Any) -> Exchange:
        """The engine's one-shot exchange, linked and marked as :meth:`transact`'s are."""
        before, seen = self.last_exchange, self.watch.late.start is not None
        first = len(self.link.transcript.events)
        ex = super().raw(text, **kw)
        self.mark_stalls([ex], first)
        return self._link_late_before(before, ex, seen)

    def mark_stalls(
        self,
        exchanges: Iterable[Exchange | None],
        first: int,
        measurements: Iterable[Measurement] = (),
    ) -> None:
        """Mark the attempts of ``exchanges`` whose reads a stall of the tool's own host may
        have held up (:func:`~conformance.tool_recorder.stalled_reads.mark_reads`), and the
        waits of ``measurements`` it may have cut (:func:`~conformance.tool_recorder.
        stalled_reads.mark_waits`), from the link's notes since its transcript's event
        ``first`` (the stimulus began there), once the link has noted what it had to (its
        reader thread resumes with the engine)."""
        found = self.stalls_since(first)
        stalled_reads.mark_reads(exchanges, found)
        stalled_reads.mark_waits(measurements, found)

    def stalls_since(self, first: int) -> list[Stall]:
        """:func:`~conformance.links.host_stall.stalls_since` of the link's transcript, read
        once per stimulus: the engine's records and the view's rebuilt ones of the same
        stimulus ask it with the same ``first`` and no event added between (truth29); a
        timed probe's case asks it over its probe's whole span (truth30,
        :meth:`~conformance.sensor.session.SensorSession.stalled_since`)."""
        self.link.reader_caught_up()
        events = self.link.transcript.events
        key = (id(events), first, len(events))
        if self._stalls_read[0] != key:
            self._stalls_read = (key, host_stall.stalls_since(events, first))
        return self._stalls_read[1]

    def _hear_late_reply(self, ex: Exchange) -> Exchange:
        """Where every try of ``ex`` went unanswered in its window and the sensor has been
        seen to start its replies late (``watch.late``), listen until that start (and a
        character) past the last try and keep the late reply heard as ``ex.heard_late``
        (:func:`~conformance.judges.late_before.late_among`): the case judges ``ex`` before
        anything else is sent, so a reply after the last try would otherwise lie in no
        record. The replies-after-retry sensor beside slow-wake met only the third try of
        each sequence, after the break's 110 ms wake-up; the last one's reply came 80 ms
        after it, and "no reply although it is a basic command: ?!" FAILed R-4.4-01, "after
        the abort M got no reply" R-4.4.5.1-03 (truth20). A sensor never seen late, or one
        that answered, is not waited for; nor an extended command (below)."""
        late = self.watch.late.start
        end = ex.last.command_end if ex.attempts else None
        if ex.answered or ex.heard_late or late is None or end is None or not ex.expect_reply:
            return ex
        if ex.command is None or ex.command.kind is _EXTENDED:
            # a multi-line text's first line is no end of it: the next command met the rest
            # as before, which the wire judge reads as the rest of a late reply talked over
            # (without this, aXHELP!'s later lines were read as 0M1!'s reply: R-4.2-02/-03,
            # R-4.3-01 FAILed beside never-standby, partial-command-accepted, ...)
            return ex
        until = end + late + CHAR_TIME + 2 * self.link.info.timing_uncertainty
        heard = self.link.receive(max(until, self.link.now()), until=bool)
        if heard and heard[-1].char7 != LF:  # the rest of it, to its LF or a pause
            heard += self.link.receive(
                heard[-1].end + LATE_START_LISTEN,
                until=lambda got: got[-1].char7 == LF,
                idle=self.policy.reply_idle,
            )
        ex.heard_late[:] = late_among(ex, heard)
        return ex

    def _link_late_before(
        self, before: Exchange | None, ex: Exchange, seen: bool = False
    ) -> Exchange:
        """Set ``ex.late_before`` to ``before`` where its last try drew no reply and the
        sensor has been seen to start its replies late (``watch.late``), before ``ex`` went
        out (``seen``) or since: a reply ``ex`` took may then be ``before``'s, the sensor deaf
        to ``ex`` until it had answered (the replies-after-retry sensor's late aD0! reply was
        read as aMC1!'s, "does not have the form atttn", beside wrong-crc, truth15). Before,
        too: that late reply, held until ``ex``'s last character ended, began 0.00 ms after
        it, and the watch counted it as a reply too soon, which cancelled the late start it
        had seen (beside slow-wake, 0MC1!'s '00002' read as 0MC2!'s: R-4.4.12-04 WARNed "0M2!
        announced 9 but 0MC2! 2", truth20). A last try whose reply characters met it (bus
        contention: the sensor's answer to the try before) drew no reply of its own either:
        behind ``--echo --jitter 2`` 0D0!'s last try met its previous try's reply, its own
        late reply was taken by 0C! and read as 0C!'s (truth28). A sensor never seen late
        links nothing."""
        if before is None or before is ex or not before.attempts:
            return ex
        before.next_sent[:] = [ex]  # its words may show ex took its late reply (taken_next)
        # a talk set aside over its last try may go on (truth37); weakly, as next_sent
        # links forward: two strong links made a cycle of every exchange a live run sent
        ex.sent_before = weakref.proxy(before)
        last = before.last
        quiet = not last.reply_events or last.reason.startswith(CONTENTION)
        if quiet and (seen or self.watch.late.start is not None):
            ex.late_before = before
        return ex

    def buffer_holds_values(self, address: str) -> bool:
        """The last command sent to ``address`` was an ASCII D read answered with values:
        its buffer holds values now (a break or standby since keeps them, R-4.4.5-10).
        A digit after the address is a value (:func:`holds_values`), even behind a wrong
        address."""
        command, reply = self.last_sent.get(address, (None, ""))
        return command is not None and command.kind is _DATA and holds_values(reply)
