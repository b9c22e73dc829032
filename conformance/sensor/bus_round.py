"""The bus cases' one stimulus (issue 23, item 2): concurrent measurements on every sensor
of a shared line at once, and their data collected in turn.

The sensor judged (the DUT) is asked ``a!`` first (shown listening), then ``aC!``; then every
other sensor its ``aC!`` and ``a!`` (whose ``b<CR><LF>`` is a service request's very shape),
each answering while the DUT's measurement runs; once the longest ttt
is out (all finished together, or near it) the others' data are collected first, a break
before each sensor's first ``aD0!``, and the DUT's last. So the DUT held its measurement
through commands to the others, their replies and their data, and everything it said in that
time is on the wire. Acts only: the judging is in ``testcases/sensor/test_bus.py``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from ..protocol.commands import parse_command
from ..tool_recorder import ToolRecorder, validity
from ..tool_recorder.records import Exchange, Measurement
from ..transcript import TOOL, Event, EventKind

#: Marking (s) after the longest ttt before the data are asked for: every sensor is done.
SETTLE = 0.1


@dataclass
class BusRound:
    """The DUT's measurement, the others' (by address), the DUT's ``a!`` before, and the
    transcript events from the end of the DUT's ``atttnn`` to the start of its ``aD0!``."""

    dut: Measurement
    others: dict[str, Measurement]
    control: Exchange
    window: list[Event]
    #: ``b!`` to each other sensor, before its ``bC!``: each answers ``b<CR><LF>``,
    #: the very shape of a service request (there is no other way to make one meet a
    #: concurrent measurement: only M-type measurements raise them)
    acks: dict[str, Exchange] = field(default_factory=dict)

    def other_replies(self, *, running: bool = False) -> list[Exchange]:
        """The others' answered exchanges (starts and data) inside the DUT's wait;
        ``running``: only those over before its ttt ran out, while its measurement could
        still be running (one that ended early cannot be told from the wire)."""
        start = self.dut.reply_end
        if start is None:
            return []
        until = start + self.dut.ttt if running and self.dut.ttt is not None else float("inf")
        out = []
        for m in self.others.values():
            for ex in (m.start, self.acks.get(m.command.address), *m.data):
                if ex is None:
                    continue
                ends = [e.end for e in ex.reply_events]
                if ex.answered and ends and start < ends[-1] < until:
                    out.append(ex)
        return out


def _tool_acts(event: Event) -> bool:
    return event.origin == TOOL and event.kind in (EventKind.BREAK, EventKind.CHAR)


def start_measurement(master: ToolRecorder, text: str) -> Measurement:
    """``text`` sent and its ``atttnn`` read (ttt and count parsed when well formed); the
    data are not asked for."""
    command = parse_command(text)
    m = Measurement(command, master.transact(command))
    parsed = validity.parse_start_reply(m.start.reply_text, validity.count_digits(command))
    if parsed is not None:
        m.ttt, m.count = parsed
    if m.start.reply_events:
        m.reply_end = m.start.reply_events[-1].end
    return m


def concurrent_round(
    master: ToolRecorder, address: str, others: Iterable[str], code: str = "C"
) -> BusRound:
    """The round described above, on ``master``'s link."""
    control = master.acknowledge(address)
    dut = start_measurement(master, f"{address}{code}!")
    acks: dict[str, Exchange] = {}
    started: dict[str, Measurement] = {}
    for other in sorted(others):  # its a! first: a command to itself would abort its own C
        acks[other] = master.acknowledge(other)
        started[other] = start_measurement(master, f"{other}{code}!")
    link = master.link
    ends = [
        m.reply_end + m.ttt for m in (dut, *started.values()) if m.reply_end is not None and m.ttt
    ]
    link.wait_until(max([link.now(), *ends]) + SETTLE)
    for m in started.values():
        master.collect(m, force_break=True)
    first = len(link.transcript.events)
    master.collect(dut, force_break=True)
    # the window ends where the DUT's collection begins: its break, or its aD0!
    asked = next((e for e in link.transcript.events[first:] if _tool_acts(e)), None)
    begin = dut.reply_end if dut.reply_end is not None else dut.start.attempts[-1].end
    until = asked.start if asked is not None else link.now()
    window = [e for e in link.transcript.events if begin <= e.start < until]
    return BusRound(dut, started, control, window, acks)


__all__ = ["BusRound", "concurrent_round", "start_measurement"]
