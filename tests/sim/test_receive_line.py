"""Issue 22, matrix18: the tool recorder reads a one-line reply on a sim link in one pass
(``SimLink.receive_line``) instead of two reads (its first character, then the rest to the
CR LF, ``ToolRecorder._listen`` and ``_rest_of_line``). The pass leaves exactly what the
two reads left: the same transcript event for event, the same attempts and reasons, the
same clock, and the device told of the same frames (its next offers the same), for the
clean emulator and every single-sensor fault, over a sequence of commands that meets
replies cut short, late, too long, service requests and breaks; and it gives way (does
nothing) wherever it cannot read so."""

from __future__ import annotations

import pytest

from conformance.emulator import FAULTS, sim_sensor
from conformance.links.base import LineEnd
from conformance.protocol import commands as cmds
from conformance.sim.bus import SimLink
from conformance.tool_recorder import ToolRecorder
from conformance.transcript import DUT, Event, EventKind, Transcript, to_wire_7e1

SINGLE = sorted(n for n, f in FAULTS.items() if not f.bus)


def _session(faults: tuple[str, ...], one_pass: bool) -> tuple[list, list, float, object]:
    bus, link, emulator = sim_sensor(faults=faults)
    if not one_pass:
        link.receive_line = None  # type: ignore[method-assign] - the two reads, as before
    master = ToolRecorder(link)
    exchanges = [master.acknowledge(), master.identify(), master.query_address()]
    for command in (cmds.measure("0"), cmds.concurrent("0", crc=True), cmds.verify("0")):
        m = master.measure(command)
        exchanges += [m.start, *m.data]
    exchanges.append(master.transact("0R0!"))
    exchanges.append(master.transact("0XZZ!", retries=False))
    exchanges.append(master.raw("0!", break_first=False))
    exchanges.append(master.acknowledge("1"))
    attempts = [
        (a.reason, a.end, a.sequence, a.retry, a.reply_events, a.stray_events)
        for ex in exchanges
        for a in ex.attempts
    ]
    return list(bus.transcript.events), attempts, bus.clock.now, emulator.next_frame()


@pytest.mark.parametrize("faults", [(), *((name,) for name in SINGLE)], ids=str)
def test_one_pass_as_two_reads(faults):
    assert _session(faults, True) == _session(faults, False)


def test_the_pass_is_taken():
    """The sessions above do read in one pass (the test would compare a path with itself)."""
    bus, link, _ = sim_sensor()
    taken = []
    line = link.receive_line

    def counted(*args):  # noqa: ANN002, ANN202 - as SimLink.receive_line
        got = line(*args)
        taken.append(got is not None)
        return got

    link.receive_line = counted  # type: ignore[method-assign]
    ToolRecorder(link).acknowledge()
    assert taken == [True]


def _reply(link: SimLink, text: str, at: float, gap: float = 0.0) -> None:
    from conformance.emulator.replies import Reply, ReplyKind

    emulator = link.bus.devices[0]
    emulator._tx.schedule(Reply(ReplyKind.CHATTER, text), at, gap)  # type: ignore[attr-defined]


def test_gives_way_where_it_cannot_read_so():
    _, link, _ = sim_sensor()
    link.bus.rx.append(Event(EventKind.CHAR, DUT, 0.0, 0.008, to_wire_7e1(0x30)))
    assert link.receive_line(1.0, lambda e: 2.0, 80, 0.01) is None  # queued first
    _, link, _ = sim_sensor()
    assert link.receive_line(1.0, lambda e: 2.0, 80, 0.01) is None  # nothing planned

    class Kept(Transcript):
        def add(self, event: Event) -> Event:
            return super().add(event)

    _, link, _ = sim_sensor()
    link.bus.transcript = link.transcript = Kept()
    _reply(link, "0\r\n", 0.01)
    assert link.receive_line(1.0, lambda e: 2.0, 80, 0.01) is None
    assert link.transcript.events == []  # nothing done


@pytest.mark.parametrize(
    ("text", "most", "deadline", "gap"),
    [("0+1\r\n", 80, 1.0, 0.0), ("0+1\r\n", 3, 1.0, 0.0), ("0+1\r\n", 1, 1.0, 0.0),
     ("0", 80, 1.0, 0.0), ("0+1\r\n", 80, 0.005, 0.0), ("0+1\r\n", 80, 1.0, 0.03),
     ("0+1\r\n", 80, 1.0, 0.06), ("0+1\r\n", 80, 0.2, 0.03), ("0+1\r\n", 80, 0.1, 0.03)],
)  # fmt: skip
def test_as_the_two_reads_at_every_stop(text, most, deadline, gap):
    """A reply cut by the limit of characters, by its CR LF, by a first character too
    late, by the end of its transmission (the second read goes on as receive does), by
    marking inside it longer than the idle (0.05 s) or not, by the read's deadline."""

    def read(one_pass: bool) -> tuple[list[Event], float]:
        _, link, _ = sim_sensor()
        _reply(link, text, 0.01, gap)
        _reply(link, "9\r\n", 0.5)  # a later transmission, after the idle
        if one_pass:
            got = link.receive_line(deadline, lambda e: e.start + deadline, most, 0.05)
            assert got is not None
        else:
            got = link.receive(deadline, until=lambda got: True)
            if got and most > 1:
                got = got + link.receive(
                    got[0].start + deadline, until=LineEnd(got, most), idle=0.05
                )
        return got, link.now(), list(link.transcript.events), link.bus.devices[0].next_frame()

    assert read(True) == read(False)


def test_gives_way_to_a_receive_of_its_own():
    """A link whose receive is wrapped (a test counting reads) reads through it."""
    _, link, _ = sim_sensor()
    _reply(link, "0\r\n", 0.01)
    link.receive = link.receive  # type: ignore[method-assign]
    assert link.receive_line(1.0, lambda e: 2.0, 80, 0.01) is None
    assert link.transcript.events == []
