"""A scripted sensor for the master-engine tests, and checks that the script does what it says.

The engine is tested against this fake rather than the emulator so each test controls exactly
what the "sensor" sends and when (bad CRC once, a late service request, 10 kB of babble),
independent of the emulator's own correctness.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import pytest

from conformance.protocol.crc import ascii_crc
from conformance.protocol.timing import CHAR_TIME
from conformance.sim.bus import Frame, SimBus, SimLink
from conformance.tool_recorder.engine import ToolRecorder
from conformance.tool_recorder.policy import Policy
from conformance.transcript import TOOL, EventKind, to_wire_7e1

REPLY_DELAY = 9e-3  # first response start bit after the command's last stop bit


@dataclass
class Burst:
    """Characters the fake sends, ``at`` seconds after the end of the command it answers.

    ``data`` as ``str`` goes out 7E1; as ``bytes`` the bytes are sent as given (8N1).
    ``bad_parity`` flips the parity bit of those character positions.
    """

    data: str | bytes
    at: float = REPLY_DELAY
    gap: float = 0.0
    bad_parity: tuple[int, ...] = ()

    def frames(self, command_end: float) -> list[Frame]:
        if isinstance(self.data, str):
            wires = [to_wire_7e1(ord(c)) for c in self.data]
        else:
            wires = list(self.data)
        for i in self.bad_parity:
            wires[i] ^= 0x80
        time = command_end + self.at
        out = []
        for wire in wires:
            out.append(Frame(time, wire))
            time += CHAR_TIME + self.gap
        return out

    @property
    def end_offset(self) -> float:
        """End of the burst's last stop bit, relative to the command end."""
        return self.at + len(self.data) * (CHAR_TIME + self.gap) - self.gap


Reply = str | bytes | Burst | list[Burst] | None
Script = dict[str, list[Reply]] | Callable[[str], Reply]


def with_crc(body: str) -> str:
    """``body`` + its ASCII CRC + CR LF."""
    return body + ascii_crc(body) + "\r\n"


def then_sr(reply: str, after: float, address: str = "0") -> list[Burst]:
    """``reply``, then a service request ``after`` s after the reply's LF."""
    first = Burst(reply)
    return [first, Burst(address + "\r\n", at=first.end_offset + after)]


class ScriptedSensor:
    """A BusDevice that answers complete commands for its address from a script.

    A dict script maps command text to successive replies (the last repeats); a callable
    script gets the command text. Breaks are recorded and drop pending output (as a real
    sensor aborting), unless ``break_cancels`` is False.
    """

    def __init__(self, script: Script, address: str = "0", *, break_cancels: bool = True) -> None:
        self.name = f"scripted-{address}"
        self.address = address
        self.script = script
        self.break_cancels = break_cancels
        self.heard: list[tuple[float, str]] = []  # (end of '!', command text)
        self.breaks: list[tuple[float, float]] = []
        self._buffer = ""
        self._counts: dict[str, int] = {}
        self._queue: deque[Frame] = deque()

    def on_break(self, start: float, end: float) -> None:
        self.breaks.append((start, end))
        self._buffer = ""
        if self.break_cancels:
            self._queue.clear()

    def on_char(self, wire: int, start: float, end: float) -> None:
        char = chr(wire & 0x7F)
        self._buffer += char
        if char != "!":
            return
        text, self._buffer = self._buffer, ""
        if not text.startswith(self.address) and not text.startswith("?"):
            return
        self.heard.append((end, text))
        frames: list[Frame] = list(self._queue)
        for burst in self._bursts(text):
            frames.extend(burst.frames(end))
        self._queue = deque(sorted(frames, key=lambda f: f.start))

    def _bursts(self, text: str) -> list[Burst]:
        if callable(self.script):
            reply = self.script(text)
        else:
            replies = self.script.get(text, [None])
            count = self._counts.get(text, 0)
            self._counts[text] = count + 1
            reply = replies[min(count, len(replies) - 1)]
        if reply is None:
            return []
        if isinstance(reply, str | bytes):
            return [Burst(reply)]
        return [reply] if isinstance(reply, Burst) else list(reply)

    def next_frame(self) -> Frame | None:
        return self._queue[0] if self._queue else None

    def pop_frame(self) -> Frame:
        return self._queue.popleft()


class Babbler:
    """A device that sends ``count`` characters back to back from ``start`` on, whatever happens."""

    name = "babbler"

    def __init__(self, count: int, start: float = 0.0, char: str = "x") -> None:
        self.remaining = count
        self.time = start
        self.wire = to_wire_7e1(ord(char))

    def on_break(self, start: float, end: float) -> None:
        pass

    def on_char(self, wire: int, start: float, end: float) -> None:
        pass

    def next_frame(self) -> Frame | None:
        return Frame(self.time, self.wire) if self.remaining else None

    def pop_frame(self) -> Frame:
        frame = Frame(self.time, self.wire)
        self.remaining -= 1
        self.time += CHAR_TIME
        return frame


def rig(*devices: object, policy: Policy | None = None) -> tuple[ToolRecorder, SimBus]:
    bus = SimBus(list(devices))  # type: ignore[arg-type]
    return ToolRecorder(SimLink(bus), policy), bus


def tool_breaks(bus: SimBus):
    return [e for e in bus.transcript if e.kind is EventKind.BREAK and e.origin == TOOL]


# -- the fake itself ---------------------------------------------------------------------------
def test_scripted_sensor_answers_in_order_and_only_its_address():
    sensor = ScriptedSensor({"0I!": ["first\r\n", "second\r\n"]})
    master, bus = rig(sensor)
    master.raw("1I!")
    assert sensor.heard == []
    assert master.raw("0I!").reply_text == "first\r\n"
    assert master.raw("0I!").reply_text == "second\r\n"
    assert master.raw("0I!").reply_text == "second\r\n"
    assert [t for _, t in sensor.heard] == ["0I!"] * 3


def test_burst_timing_and_parity_fault():
    sensor = ScriptedSensor({"0!": [Burst("0\r\n", at=12e-3, bad_parity=(0,))]})
    master, _ = rig(sensor)
    ex = master.raw("0!")
    assert ex.reply_events[0].start - ex.last.command_end == pytest.approx(12e-3)
    assert [e.parity_ok for e in ex.reply_events] == [False, True, True]


def test_babbler_stops_after_count():
    babbler = Babbler(5)
    _, bus = rig(babbler)
    bus.advance(1.0)
    assert len(bus.rx) == 5
