"""Several sensors as the served line's one device (``emulate --sensors``): the arbitration and
hearing of :class:`conformance.emulator_server.shared_line.SharedLine`, driven as the real-time
line drives it (sans-I/O: no thread, no clock) and compared with the simulated bus."""

from __future__ import annotations

import pytest

from conformance.emulator_server.command import make_bus
from conformance.emulator_server.shared_line import SharedLine
from conformance.ports import PortError
from conformance.protocol.timing import CHAR_TIME
from conformance.sim.bus import Frame
from conformance.transcript import to_wire_7e1


class _Talker:
    """A device that sends the characters it was given at their planned starts and records
    what it hears."""

    def __init__(self, name: str, plan: list[tuple[float, int]]) -> None:
        self.name = name
        self.plan = [Frame(start, wire) for start, wire in plan]
        self.heard: list[tuple[int, float, float]] = []
        self.breaks: list[tuple[float, float]] = []

    def on_break(self, start: float, end: float) -> None:
        self.breaks.append((start, end))

    def on_char(self, wire: int, start: float, end: float) -> None:
        self.heard.append((wire, start, end))

    def next_frame(self) -> Frame | None:
        return self.plan[0] if self.plan else None

    def pop_frame(self) -> Frame:
        return self.plan.pop(0)


def drain(line: SharedLine, until: float = 10.0) -> list[Frame]:
    """What the real-time line would commit, in order: each offered frame when its time
    comes (the line commits what next_frame offers, then asks again)."""
    sent = []
    while (frame := line.next_frame()) is not None and frame.start < until:
        committed = line.pop_frame()
        assert committed.start == frame.start  # the line delivers at the offered time
        sent.append(committed)
    return sent


def test_a_character_that_would_start_on_another_waits_for_the_wire():
    a = _Talker("a", [(0.0, 0x30), (CHAR_TIME, 0x31)])
    b = _Talker("b", [(0.002, 0x41)])
    sent = drain(SharedLine([a, b]))
    assert [f.wire for f in sent] == [0x30, 0x41, 0x31]  # b's planned start came before a's 2nd
    assert [f.start for f in sent] == pytest.approx([0.0, CHAR_TIME, 2 * CHAR_TIME])
    # each hears the other's characters where they went on the wire, never its own
    assert [(w, s) for w, s, _e in a.heard] == [(0x41, pytest.approx(CHAR_TIME))]
    assert [w for w, _s, _e in b.heard] == [0x30, 0x31]


def test_the_recorders_breaks_and_characters_reach_every_sensor():
    a, b, c = (_Talker(n, []) for n in "abc")
    line = SharedLine([a, b, c])
    line.on_break(0.0, 0.013)
    line.on_char(0x30, 0.03, 0.03 + CHAR_TIME)
    assert all(d.breaks == [(0.0, 0.013)] and len(d.heard) == 1 for d in (a, b, c))
    assert line.next_frame() is None


def test_a_shared_line_needs_two_sensors():
    with pytest.raises(ValueError, match="at least two"):
        SharedLine([_Talker("a", [])])


def _ask(line: SharedLine, command: str, at: float = 0.0) -> float:
    """A break, then ``command`` as the recorder sends it; the time its last stop bit ends."""
    line.on_break(at, at + 0.013)
    t = at + 0.013 + 0.009
    for char in command:
        line.on_char(to_wire_7e1(ord(char)), t, t + CHAR_TIME)
        t += CHAR_TIME
    return t


def _text(frames: list[Frame]) -> str:
    return "".join(chr(f.wire & 0x7F) for f in frames)


def test_served_sensors_answer_at_their_own_addresses_with_their_serial_numbers():
    bus = make_bus("1.4", "0,1:wrong-crc,3", "")
    assert [d.address for d in bus.devices] == ["0", "1", "3"]
    _ask(bus, "1I!")
    reply = _text(drain(bus))
    assert reply.startswith("114") and "SN0002" in reply and reply.endswith("\r\n")
    _ask(bus, "5!", at=1.0)
    assert drain(bus) == []  # nobody at 5


def test_two_sensors_at_one_address_interleave_as_on_the_simulated_bus():
    from conformance.ports import open_sim, parse_sim

    bus = make_bus("1.4", "0,0,3", "")
    _ask(bus, "0!")
    served = _text(drain(bus))
    sim = open_sim(parse_sim("sim://?sensors=0,0,3")).link
    sim.send_break(0.013)
    sim.wait_until(sim.now() + 0.009)  # the marking _ask leaves before the address
    sim.write(b"".join(bytes([to_wire_7e1(ord(c))]) for c in "0!"))
    heard = "".join(chr(e.char7) for e in sim.receive(sim.now() + 0.5))
    assert served == heard == "00\r\r\n\n"


def test_make_bus_refuses_what_sim_refuses():
    with pytest.raises(PortError, match="unknown fault"):
        make_bus("1.4", "0,1:no-such-fault", "")
    with pytest.raises(PortError, match="several sensors"):
        make_bus("1.4", "0", "")


def test_the_real_time_line_serves_each_sensor_of_the_bus():
    """The served line itself (its thread, the wall clock) with a bus on it: each sensor
    answers its own aI!, whole, and no other sensor speaks (timing is the realtime tests').
    The break and the command are put on the line at stated times, not after sleeps: a test
    thread that a busy machine held for 100 ms between the break and the command left the
    sensors in standby (R-7.0-15: 100 ms of marking), and the test failed on no fault."""
    import threading
    import time

    from conformance.emulator_server.realtime import RealTimeLine

    heard: list[tuple[float, int]] = []
    lock = threading.Lock()

    def send(data: bytes) -> None:
        with lock:
            heard.extend((time.perf_counter(), b) for b in data)

    line = RealTimeLine(make_bus("1.4", "0,1,3", ""), send).start()
    try:
        for address, serial in (("3", "SN0003"), ("1", "SN0002")):
            heard.clear()
            at = line.now()
            line.break_on(at)
            line.break_off(at + 0.013)
            line.tool_bytes(bytes(to_wire_7e1(ord(c)) for c in f"{address}I!"), at + 0.023)
            deadline = time.monotonic() + 3.0
            while not (heard and heard[-1][1] & 0x7F == 0x0A) and time.monotonic() < deadline:
                time.sleep(0.005)
            with lock:
                text = "".join(chr(b & 0x7F) for _t, b in heard)
            assert text.startswith(f"{address}14") and serial in text and text.endswith("\r\n")
            assert text.count("\n") == 1, text
    finally:
        line.stop()
