"""What the sensor's data buffer is known to hold, from what the tool last sent it.

A case that must tell kept data from cleared data (an aborted measurement whose D replies
should be empty) needs values in the buffer before it starts: a sensor that wrongly keeps the
previous data looks conforming when the previous data were empty. What the buffer holds when a
case starts was left by whichever case ran before it, so such a case asks for a filled buffer
explicitly; this watch lets the session say "already filled" without sending anything.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..links.base import Link
from ..protocol.commands import Command, Kind
from ..protocol.responses import holds_values
from ..tool_recorder.engine import ToolRecorder
from ..tool_recorder.hooks import Engine, Hooks
from ..tool_recorder.policy import Policy
from ..tool_recorder.records import Attempt, Exchange
from ..transcript import SEVEN_BITS
from .late_watch import LateStartWatch


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

    def transact(self, command: Command | str, **kw: Any) -> Exchange:
        """The engine's exchange, linked to the one before it where that may have answered
        late (:meth:`_link_late_before`); measurements' starts and D reads come here too."""
        before = self.last_exchange
        return self._link_late_before(before, super().transact(command, **kw))

    def raw(self, text: str | bytes, **kw: Any) -> Exchange:
        """The engine's one-shot exchange, linked as :meth:`transact`'s are."""
        before = self.last_exchange
        return self._link_late_before(before, super().raw(text, **kw))

    def _link_late_before(self, before: Exchange | None, ex: Exchange) -> Exchange:
        """Set ``ex.late_before`` to ``before`` where its last try drew no reply and the
        sensor has been seen to start its replies late (``watch.late``): a reply ``ex`` took
        may then be ``before``'s, the sensor deaf to ``ex`` until it had answered (the
        replies-after-retry sensor's late aD0! reply was read as aMC1!'s, "does not have the
        form atttn", beside wrong-crc, truth15). A sensor never seen late links nothing."""
        if before is None or before is ex or not before.attempts:
            return ex
        before.next_sent[:] = [ex]  # its words may show ex took its late reply (taken_next)
        if not before.last.reply_events and self.watch.late.start is not None:
            ex.late_before = before
        return ex

    def buffer_holds_values(self, address: str) -> bool:
        """The last command sent to ``address`` was an ASCII D read answered with values:
        its buffer holds values now (a break or standby since keeps them, R-4.4.5-10).
        A digit after the address is a value (:func:`holds_values`), even behind a wrong
        address."""
        command, reply = self.last_sent.get(address, (None, ""))
        return command is not None and command.kind is Kind.DATA and holds_values(reply)
