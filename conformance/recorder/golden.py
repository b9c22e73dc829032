"""The golden recorder: the tool recorder exposed as a recorder under test.

A recorder program is any callable ``(request, link) -> RecorderOutput``: it receives what the
scenario asks (:class:`~conformance.recorder_jobs.Request`) and the bus, does the job the
way a data logger would, and says what it logged. :class:`GoldenRecorder` does it with the
tool's own :class:`~conformance.tool_recorder.ToolRecorder` under :meth:`Policy.golden`, so it
is the reference every recorder judge must find COMPLIANT; its knobs (and the engine hooks in
:mod:`conformance.recorder.faults`) make the faulty recorders of the fault-detection matrix.

Beyond what the engine does per command, a logger has duties across commands, kept here:
issue the measurement again after a valid empty D reply (R-4.4.8-05), start concurrent
measurements together and collect each after its own ttt (R-4.4.7-06), and pass host commands
through transparently with a break in front (R-4.4.14-01/02).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..links.base import Link
from ..protocol.binary import parse_binary_packet
from ..protocol.commands import Command, Kind, parse_command
from ..protocol.values import split_values
from ..recorder_jobs import RecorderOutput, Request, Task
from ..tool_recorder import Measurement, Policy, ToolRecorder, validity
from ..tool_recorder.hooks import Engine, Hooks
from ..tool_recorder.records import Exchange
from ..transcript import TOOL, EventKind

RecorderProgram = Callable[[Request, Link], RecorderOutput]
MasterFactory = Callable[[Link, Policy], ToolRecorder]

#: Longest the golden recorder waits for a babbling sensor to fall quiet before a retry.
MAX_DRAIN = 1.0


class GoldenHooks(Hooks):
    """The engine as a recorder under test: before a retry it lets an invalid reply finish.

    The engine stops reading a reply after 8.33 ms of marking (a retry trigger, R-7.2-05), but
    a sensor may resume after such a pause; a recorder must not talk over it (R-7.2-06). So
    the retry waits until the line has been quiet for ``retry_gap`` after the sensor's last
    character, keeping the late characters with the attempt they belong to. The faulty
    recorders' hooks (:mod:`conformance.recorder.faults`) build on these.
    """

    def retry_time(
        self,
        master: Engine,
        exchange: Exchange,
        sequence: int,
        per_sequence: int,
        usual: Callable[[], float],
    ) -> float:
        """The engine's retry time, once the line has been quiet for ``retry_gap``."""
        prev = exchange.last
        link = master.link
        if prev.reply_events:
            quiet = master.policy.retry_gap
            limit = link.now() + MAX_DRAIN
            while (last := _last_sensor_char(link)) + quiet > link.now() < limit:
                prev.reply_events += link.receive(min(last + quiet, limit))
        return max(usual(), link.now())


class GoldenToolRecorder(ToolRecorder):
    """The engine with :class:`GoldenHooks` (or ``hooks`` built on them): the golden recorder's
    engine, and the faulty recorders' unless they pass hooks of their own."""

    def __init__(
        self,
        link: Link,
        policy: Policy | None = None,
        *,
        address: str = "0",
        hooks: Hooks | None = None,
    ) -> None:
        super().__init__(
            link, policy, address=address, hooks=hooks if hooks is not None else GoldenHooks()
        )


def _last_sensor_char(link: Link) -> float:
    """End of the last character the sensor sent, or -inf."""
    for event in reversed(link.transcript.events):
        if event.kind is EventKind.CHAR and event.origin != TOOL:
            return event.end
    return float("-inf")


@dataclass
class GoldenRecorder:
    """The reference recorder program (and, with other settings, its faulty twins).

    ``wait``: how ``aM!``-type measurements wait for data ("auto": the service request or
    ttt, whichever first; "ttt": always the full ttt). ``ttt_fraction`` scales the wait before
    collecting concurrent data (1 = the full ttt). ``reissues``: how often a measurement is
    issued again after a valid empty D reply. ``transparent_break``: whether a host command
    relayed in transparent mode gets a break of its own (R-4.4.14-01); False leaves it to the
    engine's break rules (a new address, 87 ms of marking). A knob rather than a ``__call__``
    of its own, so the loggers that rewrite what they send (faults.RewritingRecorder) relay
    without a break too when a fault says so.
    """

    policy: Policy | None = None
    master_factory: MasterFactory = GoldenToolRecorder
    wait: str = "auto"
    ttt_fraction: float = 1.0
    reissues: int = 2
    transparent_break: bool = True

    def __call__(self, request: Request, link: Link) -> RecorderOutput:
        master = self.master_factory(link, self.policy or Policy.golden())
        out = RecorderOutput()
        match request.task:
            case Task.MEASURE:
                for text in request.commands:
                    out.logged[text] = self._measure(master, parse_command(text))
            case Task.CONCURRENT:
                self._concurrent(master, request.commands, out)
            case Task.COMMAND:
                for text in request.commands:
                    ex = master.transact(parse_command(text))
                    out.relayed[text] = ex.reply_text if ex.ok else ""
            case Task.TRANSPARENT:
                for text in request.commands:
                    # the host's command goes out as typed, woken by a break (R-4.4.14-01)
                    brk = self.transparent_break
                    ex = master.transact(parse_command(text), force_break=brk)
                    out.relayed[text] = ex.reply_text if ex.answered else ""
        return out

    # -- measurements ----------------------------------------------------------------------
    def _measure(self, master: ToolRecorder, command: Command) -> list[str]:
        if command.kind is Kind.CONTINUOUS:  # aRn!: the values come in the reply itself
            ex = master.transact(command)
            text = validity.data_values_text(ex.reply_text, command.crc) if ex.ok else ""
            return split_values(text)
        m = master.measure(command, wait=self.wait)
        for _ in range(self.reissues):
            if not _stopped_on_empty(m):
                break
            m = master.measure(command, wait=self.wait)  # R-4.4.8-05
        return logged_values(m)

    def _concurrent(
        self, master: ToolRecorder, texts: tuple[str, ...], out: RecorderOutput
    ) -> None:
        started = [
            master.measure(parse_command(text), collect=False, wait="none") for text in texts
        ]
        pending = [m for m in started if m.count is not None]
        pending.sort(key=self._data_time)
        for m in pending:
            if m.ttt:
                master.link.wait_until(self._data_time(m))
            master.collect(m, force_break=True)
        for text, m in zip(texts, started, strict=True):
            out.logged[text] = logged_values(m)

    def _data_time(self, m: Measurement) -> float:
        """When a concurrent measurement's data may be read: ttt after its reply (R-4.4.7-06)."""
        assert m.reply_end is not None and m.ttt is not None
        margin = (self.policy or Policy.golden()).ttt_margin
        return m.reply_end + m.ttt * self.ttt_fraction + margin


def _stopped_on_empty(m: Measurement) -> bool:
    """Collection ended on a valid reply that held no values while values were still due."""
    if m.complete or not m.data or not m.data[-1].ok or m.binary:
        return False
    last = m.data[-1]
    return validity.data_values_text(last.reply_text, m.command.returns_crc) == ""


def logged_values(m: Measurement) -> list[str]:
    """The values a logger would store: D values as sent, HB packet values as numbers."""
    if m.command.kind is not Kind.HIGH_VOLUME_BINARY:
        return list(m.values)
    values: list[str] = []
    for packet in m.packets:
        values += [repr(v) for v in parse_binary_packet(packet).values]
    return values


def golden_recorder() -> GoldenRecorder:
    """The default recorder under test on ``--port sim``: COMPLIANT by construction."""
    return GoldenRecorder()
