"""The sim bus's run of planned frames (``SimBus.planned_run``, ``SimLink._take_run``) puts
on the wire exactly what asking the device frame by frame puts there: the same events, the
same stamps, the same clock, the same device state after. Every emulator fault's own wire
check runs both ways and the transcripts are compared."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.emulator import FAULTS, default_profile
from conformance.emulator.replies import Reply, ReplyKind
from conformance.emulator.transmitter import Transmission, Transmitter
from conformance.sim.bus import SimBus, SimLink
from tests.emulator.test_faults import CHECKS
from tests.emulator.test_sensor import Rig
from tests.support.transmitter_device import TransmitterDevice


def _frame_by_frame(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(SimBus, "planned_run", lambda self: None)


def _checked(name: str | None) -> tuple[list, str, int]:
    """The transcript of a fault's wire check (or of the clean emulator failing it), the
    check's outcome and how many characters went through a planned run."""
    version = FAULTS[name].version if name else FAULTS[sorted(FAULTS)[0]].version
    rig = Rig(default_profile(version), (name,) if name else ())
    runs = []
    take = SimLink._take_run

    def counted(self, run, got, *args):  # noqa: ANN001, ANN202 - as SimLink._take_run
        before = len(got)
        try:
            return take(self, run, got, *args)
        finally:
            runs.append(len(got) - before)

    SimLink._take_run = counted  # type: ignore[method-assign]
    try:
        CHECKS[name or sorted(FAULTS)[0]](rig)
        outcome = "passed"
    except AssertionError as exc:
        outcome = f"failed: {exc}"
    finally:
        SimLink._take_run = take  # type: ignore[method-assign]
    return list(rig.bus.transcript.events), outcome, sum(runs)


@pytest.mark.parametrize("name", sorted(FAULTS))
def test_a_planned_run_is_what_frame_by_frame_gives(name: str, monkeypatch) -> None:
    fast, fast_outcome, in_runs = _checked(name)
    _frame_by_frame(monkeypatch)
    slow, slow_outcome, none = _checked(name)
    assert none == 0
    assert fast == slow
    assert fast_outcome == slow_outcome
    if any(e.origin == "dut" for e in fast):
        assert in_runs > 0  # the run was taken, so the comparison compared something


def test_the_clean_emulator_is_the_same_both_ways(monkeypatch) -> None:
    fast, _, in_runs = _checked(None)
    _frame_by_frame(monkeypatch)
    assert _checked(None)[0] == fast
    assert in_runs > 0


def test_the_rest_of_a_transmission_is_each_frame_in_turn() -> None:
    reply = Reply(ReplyKind.DATA, "0+1.25+3.5")
    for gap, pauses, char_time in [(0.0, (), 8.33e-3), (1.7e-3, ((4, 0.3),), 8.33e-3),
                                   (0.4e-3, ((1, 0.011),), 9.1e-3),
                                   (0.0, ((2, 0.004), (7, 0.002)), 8.33e-3)]:  # fmt: skip
        item = Transmission(reply, 1.234567, reply.wires(), gap, char_time=char_time, pauses=pauses)
        for sent in range(len(item.wires)):
            item.sent = sent
            expected = [item.frame(i) for i in range(sent, len(item.wires))]
            got = list(item.rest())
            assert got == [(f.start, f.wire, f.duration) for f in expected]


def test_frames_whose_ends_might_fall_are_asked_one_by_one() -> None:
    reply = Reply(ReplyKind.DATA, "0+1")
    tx = Transmitter()
    tx.schedule(reply, 1.0, gap=-0.009)
    assert tx.ahead() is None
    tx = Transmitter()
    tx.schedule(reply, 1.0, gap=0.0, pauses=((2, -0.001),))
    assert tx.ahead() is None
    tx = Transmitter()
    assert tx.ahead() is None
    tx.schedule(reply, 1.0, gap=0.0)
    assert tx.ahead() is not None


def test_popping_a_run_is_popping_each_frame() -> None:
    reply = Reply(ReplyKind.DATA, "0+1.5")
    one, many = Transmitter(), Transmitter()
    for tx in (one, many):
        tx.schedule(reply, 0.5, gap=0.001, pauses=((3, 0.02),))
        tx.schedule(reply, 2.0, gap=0.0)
    for _ in range(4):
        frame, _item = one.pop_frame()
    end, item = many.pop_frames(4)
    assert end == frame.start + frame.duration
    assert item.sent == 4 and one.next_frame() == many.next_frame()
    rest = len(item.wires) - 4
    for _ in range(rest):
        one.pop_frame()
    end, item = many.pop_frames(rest)
    assert item.done and len(many.queue) == 1 and one.next_frame() == many.next_frame()


class _Talker(TransmitterDevice):
    """A device that only talks: its planned replies, offered either way."""

    def __init__(self) -> None:
        super().__init__()
        self.tx.schedule(Reply(ReplyKind.DATA, "0+1.5+2.25"), 0.010, gap=0.0004)
        self.tx.schedule(Reply(ReplyKind.DATA, "0+3"), 0.050, gap=0.0, pauses=((3, 0.045),))
        self.tx.schedule(Reply(ReplyKind.DATA, "0+77.125"), 0.500, gap=0.021)
        self.tx.schedule(Reply(ReplyKind.SERVICE_REQUEST, "0"), 0.900, gap=0.0)


READS = [  # (how far the deadline lies, stop after how many characters, idle)
    (0.005, None, None), (0.02, 1, None), (1.0, 3, 0.02), (1.0, None, 0.02), (0.3, None, 0.05),
    (1.0, 2, 0.0), (1.0, None, 0.03), (0.01, None, None), (2.0, None, None),
]  # fmt: skip


def _reads(planned: bool, monkeypatch: pytest.MonkeyPatch, restamp: bool = False) -> list:
    if not planned:
        _frame_by_frame(monkeypatch)
    link = SimLink(SimBus([_Talker()]))
    if restamp:  # as tests/judges/test_confirmation.py models a stalling host: some late
        add, heard = link.transcript.add, [0]

        def stamped(event):  # noqa: ANN001, ANN202 - as Transcript.add
            if event.origin == "dut":
                heard[0] += 1
                if heard[0] % 3 == 0:
                    event = replace(event, start=event.start + 0.03, end=event.end + 0.03)
            return add(event)

        link.transcript.add = stamped  # type: ignore[method-assign]
    found = []
    for ahead, count, idle in READS:
        until = None if count is None else (lambda got, n=count: len(got) >= n)
        got = link.receive(link.now() + ahead, until=until, idle=idle)
        found.append(([(e.start, e.end, e.wire) for e in got], link.now()))
    monkeypatch.undo()
    return [found, list(link.transcript.events)]


def test_reads_with_idle_windows_and_stops_end_where_they_ended(monkeypatch) -> None:
    """Idle windows that close inside a reply's pause, stops after some characters,
    deadlines inside a reply: each read returns the same characters and leaves the clock
    where frame by frame left it."""
    assert _reads(True, monkeypatch) == _reads(False, monkeypatch)


def test_a_transcript_that_restamps_what_it_is_given_is_read_as_it_restamped(
    monkeypatch,
) -> None:
    """A read returns (and times its idle window from) the event the transcript's ``add``
    returned, in a run as frame by frame: a test models a stalling host that way."""
    restamped = _reads(True, monkeypatch, restamp=True)
    assert restamped == _reads(False, monkeypatch, restamp=True)
    assert restamped != _reads(True, monkeypatch)  # the restamping changed the reads


def test_a_wire_event_is_the_event_its_constructor_makes() -> None:
    """transcript.wire_event, the sim bus's fast way to make a character, sets every field
    as ``Event(kind, origin, start, end, wire=wire)`` does, defaults included: a field added
    to Event without it here fails this test."""
    import dataclasses
    import random

    from conformance.transcript import TOOL, Event, EventKind, wire_event

    fields = dataclasses.fields(Event)
    assert [f.name for f in fields] == list(Event.__slots__)
    rng = random.Random(4)
    for _ in range(500):
        args = (rng.choice(list(EventKind)), rng.choice([TOOL, "dut", "sensor-1"]),
                rng.random(), rng.random() + 1.0, rng.randrange(256))  # fmt: skip
        fast, made = wire_event(*args), Event(*args[:4], wire=args[4])
        assert fast == made and hash(fast) == hash(made) and repr(fast) == repr(made)
        for f in fields:
            assert type(getattr(fast, f.name)) is type(getattr(made, f.name))
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.start = 0.0  # type: ignore[misc]


def test_a_full_event_is_an_event_like_any_other() -> None:
    """transcript.full_event makes an :class:`_Unfrozen` object and turns it into an Event
    (matrix21): what it gives must be the constructor's event in every way a reader can
    tell, every field set, its type Event itself, frozen, equal and hashed alike, and the
    same after a pickle round trip and a copy (a rack worker's results cross processes)."""
    import copy
    import dataclasses
    import pickle
    import random

    from conformance.transcript import TOOL, Event, EventKind, full_event

    fields = dataclasses.fields(Event)
    rng = random.Random(21)
    for _ in range(500):
        args = (rng.choice(list(EventKind)), rng.choice([TOOL, "dut", "bus"]), rng.random(),
                rng.random() + 1.0, rng.randrange(512), rng.choice(["", "collision", "x"]),
                rng.choice([0.0, rng.random() * 1e-3]), rng.choice([None, 0.0, 2e-4]))  # fmt: skip
        fast, made = full_event(*args), Event(*args)
        assert type(fast) is Event and isinstance(fast, Event)
        assert fast == made and hash(fast) == hash(made) and repr(fast) == repr(made)
        for f in fields:
            assert getattr(fast, f.name) == getattr(made, f.name)
            assert type(getattr(fast, f.name)) is type(getattr(made, f.name))
        again = pickle.loads(pickle.dumps(fast))
        assert type(again) is Event and again == made
        assert copy.copy(fast) == made and copy.deepcopy(fast) == made
        assert fast.to_json() == made.to_json()
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.start = 0.0  # type: ignore[misc]
    assert not hasattr(fast, "__dict__")  # the slots only, as the constructor's


def _one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """The tool's characters placed as ``SimLink.write`` placed them before ``tool_run``:
    each by :meth:`SimBus.tool_char`, the next ``gap`` after the end of the kept event."""

    def each(self, wires, start, gap):  # noqa: ANN001, ANN202 - as SimBus.tool_run
        events, time = [], start
        for wire in wires:
            event = self.tool_char(wire, time)
            events.append(event)
            time = event.end + gap
        return events

    monkeypatch.setattr(SimBus, "tool_run", each)


def _written(name: str | None) -> tuple[list, str, int]:
    """:func:`_checked`, with the count of the tool's characters ``tool_run`` placed."""
    placed = []
    run = SimBus.tool_run

    def counted(self, wires, start, gap):  # noqa: ANN001, ANN202 - as SimBus.tool_run
        events = run(self, wires, start, gap)
        placed.append(len(events))
        return events

    SimBus.tool_run = counted  # type: ignore[method-assign]
    try:
        events, outcome, _ = _checked(name)
    finally:
        SimBus.tool_run = run  # type: ignore[method-assign]
    return events, outcome, sum(placed)


@pytest.mark.parametrize("name", [None, *sorted(FAULTS)])
def test_a_command_written_in_one_run_is_what_char_by_char_gives(name, monkeypatch) -> None:
    """R-7.0-13 and every rule a command's timing feeds rest on the tool's characters'
    stamps: ``SimBus.tool_run`` (a command's characters in one loop) puts on the wire exactly
    what ``tool_char`` one by one put there, with every emulator fault's wire check (the
    sensors' own hearing included: a fault that answers early or mid-command)."""
    fast, fast_outcome, placed = _written(name)
    _one_by_one(monkeypatch)
    slow, slow_outcome, _ = _written(name)
    assert fast == slow
    assert fast_outcome == slow_outcome
    assert placed == sum(e.origin == "tool" and e.kind.name == "CHAR" for e in fast) > 0


def test_a_command_with_gaps_and_a_restamping_transcript_is_written_as_before(
    monkeypatch,
) -> None:
    """Gaps between the command's characters, a device talking across the command, and a
    transcript whose ``add`` restamps what it is given (a stalling host): each next
    character starts ``gap`` after the end of the event the transcript kept, as before."""

    def written(one_by_one: bool) -> list:
        if one_by_one:
            _one_by_one(monkeypatch)
        link = SimLink(SimBus([_Talker()]))
        add, count = link.transcript.add, [0]

        def stamped(event):  # noqa: ANN001, ANN202 - as Transcript.add
            count[0] += 1
            if event.origin == "tool" and count[0] % 4 == 0:
                event = replace(event, start=event.start + 0.002, end=event.end + 0.002)
            return add(event)

        link.transcript.add = stamped  # type: ignore[method-assign]
        found = []
        for wires, gap in ((b"0M!", 0.0), (b"0D0!", 0.003), (b"0R0!", 0.0015)):
            link.wait_until(link.now() + 0.004)
            sent = link.write(wires, gap)
            found.append([(e.start, e.end, e.wire) for e in sent])
        monkeypatch.undo()
        return [found, link.now(), list(link.transcript.events)]

    assert written(False) == written(True)


def _windowed(link: SimLink, deadline: float, stop: object, idle: float) -> list:
    """A ``LineEnd`` read on from characters before it, as the tool recorder's loop read one
    before ``reads_line_at_once``: a receive per ``idle`` window after the last character
    so far, its stop a plain function called per character. What the sim link's one read
    (the idle counted from ``stop.before``'s last) must come to."""
    from conformance.links.base import LineEnd

    got: list = []
    while True:
        before = stop.before + got  # type: ignore[attr-defined]
        window = LineEnd(before, stop.most)  # type: ignore[attr-defined]
        more = link.receive(
            min(deadline, before[-1].end + idle), until=lambda g, s=window: s(g), idle=idle
        )
        got += more
        if not more or window(more):
            return got


def _line_reads(inline: bool, restamp: bool = False) -> list:
    """Reads of ``_Talker``'s replies each stopped by a ``LineEnd`` (as the tool recorder
    reads a one-line reply), checked inline by the sim link's run (``inline``) or called
    after each character as any other stop condition is (a plain function around it)."""
    from conformance.links.base import LineEnd

    link = SimLink(SimBus([_Talker()]))
    if restamp:
        add, heard = link.transcript.add, [0]

        def stamped(event):  # noqa: ANN001, ANN202 - as Transcript.add
            heard[0] += 1
            if heard[0] % 3 == 0:
                event = replace(event, start=event.start + 0.03, end=event.end + 0.03)
            return add(event)

        link.transcript.add = stamped  # type: ignore[method-assign]
    found, before = [], []
    for ahead, most, idle, fresh in [
        (0.02, 99, None, True), (1.0, 5, 0.02, False), (1.0, 99, 0.05, False),
        (1.0, 3, None, True), (1.0, 99, 0.03, False), (2.0, 99, None, False),
    ]:  # fmt: skip
        if fresh:
            before = []
        stop = LineEnd(list(before), most)
        if inline:
            got = link.receive(link.now() + ahead, until=stop, idle=idle)
        elif idle is not None and before:
            got = _windowed(link, link.now() + ahead, stop, idle)
        else:
            got = link.receive(link.now() + ahead, until=lambda g, s=stop: s(g), idle=idle)
        before += got
        found.append(([(e.start, e.end, e.wire) for e in got], link.now()))
    return [found, list(link.transcript.events)]


def test_a_line_end_checked_inline_stops_where_its_call_stops(monkeypatch) -> None:
    """The tool recorder's one-line reply read (``LineEnd``: R-4.2-02's CR LF, or the most
    characters it takes) stops at the same character, leaves the same clock and the same
    transcript whether the sim link's run checks it inline or calls it per character, with
    the transcript's own ``add`` and with one that restamps (which the run then calls)."""
    from conformance.links.base import LineEnd

    for restamp in (False, True):
        assert _line_reads(True, restamp) == _line_reads(False, restamp)
    assert _line_reads(True) != _line_reads(True, restamp=True)  # the restamping counted
    calls, call = [], LineEnd.__call__

    def counted(self, got):  # noqa: ANN001, ANN202 - as LineEnd.__call__
        calls.append(len(got))
        return call(self, got)

    monkeypatch.setattr(LineEnd, "__call__", counted)
    _line_reads(True)
    assert calls == []  # inline: never called
    _line_reads(False)
    assert calls  # called: the comparison above compared two ways


def test_a_line_end_is_the_framing_s_stop_after() -> None:
    """``Framing.stop_for`` of a one-line 7E1 reply is a ``LineEnd`` that answers as
    ``Framing.stop_after`` does, character by character, at every split of a reply (CR LF
    at the end, a CR alone, a reply cut at the most characters)."""
    from conformance.links.base import LineEnd
    from conformance.tool_recorder.reply_end import Framing
    from conformance.transcript import Event, EventKind

    framing = Framing(idle=0.0083, max_chars=9)
    for text in ("0+1.5\r\n", "0\r\r\n", "0+1\r+2\n\r\n", "0123456789012\r\n", "\n\r\n"):
        chars = [Event(EventKind.CHAR, "dut", i, i + 1, wire=ord(c)) for i, c in enumerate(text)]
        for cut in range(len(chars)):
            have = chars[:cut]
            stop = framing.stop_for(have)
            assert isinstance(stop, LineEnd)
            for more in range(cut + 1, len(chars) + 1):
                got = chars[cut:more]
                assert stop(got) == framing.stop_after(have, got), (text, cut, more)
    assert not isinstance(Framing(idle=0.01, max_chars=9, binary=True).stop_for([]), LineEnd)
    assert not isinstance(Framing(idle=0.01, max_chars=9, multiline=True).stop_for([]), LineEnd)
