"""Telling the tool's own echoed characters from the DUT's (sans-I/O).

On a single-wire interface that hears itself (a diode-and-resistor UART adapter, a level
shifter whose receiver stays on), every character the tool sends comes back, and spacing (a
break) comes back as a 0x00 read with a framing error (a short pulse as a byte whose low bits
are 0). Those bytes are the tool's, never the DUT's: :class:`EchoTracker` is told what the tool
is sending and sorts each received byte into an echo of it, the DUT's, or a collision (the line
carried something other than what the tool sent: the DUT talked over it).

``auto`` decides on the first transmission of characters: if every character comes back in
order the interface echoes; the first byte that does not match, or silence, says it does not.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from enum import StrEnum


class EchoMode(StrEnum):
    AUTO = "auto"
    ON = "on"
    OFF = "off"


def is_spacing_echo(byte: int) -> bool:
    """0x00 (a break), or low data bits 0 and the rest 1 (a shorter spacing pulse)."""
    return any(byte == (0xFF << k) & 0xFF for k in range(1, 9))


@dataclass(frozen=True)
class Expected:
    """One thing the tool put on the line: a character (``byte``) or spacing (None)."""

    byte: int | None
    frame: float  # s: its length at the rate it was sent


@dataclass(frozen=True)
class Heard:
    """A received byte, sorted: ``origin`` is "tool" (an echo) or "dut"."""

    origin: str
    byte: int
    end: float  # s: arrival stamp
    expected: Expected | None = None  # what it echoes (tool), or what it collided with (dut)
    note: str = ""


class EchoTracker:
    """Sorts received bytes while the tool transmits. Not thread-safe: the link calls it
    under its own lock."""

    def __init__(self, mode: EchoMode = EchoMode.AUTO) -> None:
        self.mode = mode
        self.decided = mode is not EchoMode.AUTO
        self.echoes = mode is EchoMode.ON
        self._pending: deque[Expected] = deque()
        self._held: list[Heard] = []  # matched while auto has not decided yet
        self._chars_expected = 0  # characters in the transmission that decides auto
        self.collisions = 0
        self.missing = 0

    @property
    def listening(self) -> bool:
        """Whether received bytes may be echoes (echo on, or auto still deciding)."""
        return self.echoes or not self.decided

    @property
    def pending(self) -> int:
        return len(self._pending)

    def expect(self, items: list[Expected]) -> None:
        """The tool is about to send ``items``."""
        if not self.listening:
            return
        self._pending.extend(items)
        if not self.decided:
            self._chars_expected += sum(1 for e in items if e.byte is not None)

    def heard(self, byte: int, end: float) -> list[Heard]:
        """Sort one received byte; returns what to record now, in order (bytes held while
        auto decides come out together once it has)."""
        while self._pending and self.listening:
            want = self._pending[0]
            if want.byte is None:  # spacing: echoed as a zero-prefix byte, or not at all
                self._pending.popleft()
                if is_spacing_echo(byte):
                    return self._matched(Heard("tool", byte, end, want))
                continue
            if byte == want.byte:
                self._pending.popleft()
                return self._matched(Heard("tool", byte, end, want))
            if not self.decided:
                return self._decide(False, [Heard("dut", byte, end)])
            self._pending.popleft()
            self.collisions += 1
            note = (
                f"echo differs: the tool sent {_show(want.byte)}, the line carried "
                f"{_show(byte)} (a collision: the DUT talked over the tool)"
            )
            # the tool's character was sent all the same; what the line carried is the DUT's
            return [Heard("tool", want.byte, end, want), Heard("dut", byte, end, want, note)]
        return [Heard("dut", byte, end)]

    def expire(self) -> list[str]:
        """The time for the pending echoes is over: notes on what never came back (and, for
        auto, the decision)."""
        notes: list[str] = []
        missing = [e for e in self._pending if e.byte is not None]
        self._pending.clear()
        if not self.decided:
            # a real echo brings every character back in order well within the time; a partial
            # match is the DUT's reply starting like the command (its address): not an echo
            self._held = self._decide(False, [])
            return ["no echo of the tool's characters: the interface does not echo"]
        for e in missing:
            self.missing += 1
            notes.append(f"echo of {_show(e.byte)} not heard (lost, or the line was held)")
        return notes

    def release(self) -> list[Heard]:
        """Bytes held while deciding (when the decision came from :meth:`expire`)."""
        held, self._held = self._held, []
        return held

    # -- internals ------------------------------------------------------------------------------
    def _matched(self, heard: Heard) -> list[Heard]:
        if self.decided:
            return [heard]
        self._held.append(heard)
        chars = sum(1 for h in self._held if h.expected and h.expected.byte is not None)
        if self._chars_expected and chars >= self._chars_expected:
            return self._decide(True, [])
        return []

    def _decide(self, echoes: bool, then: list[Heard]) -> list[Heard]:
        self.decided, self.echoes = True, echoes
        held, self._held = self._held, []
        if not echoes:
            self._pending.clear()
            held = [Heard("dut", h.byte, h.end) for h in held]
        return held + then


def _show(byte: int | None) -> str:
    if byte is None:
        return "spacing"
    if 0x20 <= byte < 0x7F:
        return repr(chr(byte))
    return f"0x{byte:02X}"
