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

#: s: spacing this long reads as 0x00 at 1200 baud (a framing error: 8.5 bit times), so a
#: break's echo still owed behind the DUT's bytes is that byte and no other: '@', 'p' and
#: '|' with their parity are zero-prefix bytes too, and a reply's CRC may hold them
BREAK_READ = 8.5 / 1200


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
    expected: Expected | None = None  # what it echoes (tool)
    note: str = ""
    collided: bool = False  # the DUT's, received between echoes of the tool's characters


class EchoTracker:
    """Sorts received bytes while the tool transmits. Not thread-safe: the link calls it
    under its own lock."""

    def __init__(self, mode: EchoMode = EchoMode.AUTO) -> None:
        self.mode = mode
        self.decided = mode is not EchoMode.AUTO
        self.echoes = mode is EchoMode.ON
        self._pending: deque[Expected] = deque()
        self._held: list[Heard] = []  # matched while auto has not decided yet
        self._window: list[tuple[int, float]] = []  # received while a decided echo is due
        self._chars_expected = 0  # characters in the transmission that decides auto
        #: a break whose echo was still due when a byte of the DUT's came first (its late
        #: reply, delivered behind a stall, or one the break met): the echo comes behind it
        self._owed: Expected | None = None
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
        if any(e.byte is None for e in items):
            self._owed = None  # a new break: the one before's echo is no longer awaited
        self._pending.extend(items)
        if not self.decided:
            self._chars_expected += sum(1 for e in items if e.byte is not None)

    def heard(self, byte: int, end: float) -> list[Heard]:
        """Sort one received byte; returns what to record now, in order (bytes held while
        auto decides, or while a decided echo is still coming back, come out together once
        they are sorted)."""
        owed = self._owed
        if owed is not None and byte == 0x00 and not self._window:
            # the break's echo, behind the DUT's bytes that came before it (truth25: under
            # host stalls a late reply's rest came between a break and its echo, and the
            # echo was recorded as a 0x00 of the DUT's, ahead of the next reply)
            self._owed = None
            return [Heard("tool", byte, end, owed)]
        while self._pending and self.listening:
            want = self._pending[0]
            if want.byte is None:  # spacing: echoed as a zero-prefix byte, or not at all
                self._pending.popleft()
                if is_spacing_echo(byte):
                    return self._matched(Heard("tool", byte, end, want))
                if self.decided and want.frame >= BREAK_READ:  # its 0x00 may come behind
                    self._owed = want
                continue
            if not self.decided:
                if byte == want.byte:
                    self._pending.popleft()
                    return self._matched(Heard("tool", byte, end, want))
                return self._decide(False, [Heard("dut", byte, end)])
            if want.byte == 0x00 and not self._window:  # a UART-timed pulse: one NUL alone
                self._pending.popleft()
                if is_spacing_echo(byte):
                    return [Heard("tool", byte, end, want)]
                self.collisions += 1
                note = (
                    f"echo differs: the tool sent a NUL pulse, the line carried {_show(byte)} "
                    "(a collision: the DUT talked over the tool)"
                )
                return [Heard("tool", 0x00, end, want), Heard("dut", byte, end, note=note)]
            return self._window_add(byte, end)
        return [Heard("dut", byte, end)]

    def expire(self) -> list[str]:
        """The time for the pending echoes is over: notes on what never came back (and, for
        auto, the decision)."""
        notes: list[str] = []
        self._owed = None
        if self._window:
            self._held = self._sort_window()
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
        """Bytes held while deciding or while the echo was coming back (when
        :meth:`expire` ended the wait)."""
        held, self._held = self._held, []
        return held

    # -- internals ------------------------------------------------------------------------------
    def _window_add(self, byte: int, end: float) -> list[Heard]:
        """Hold a byte received while the tool's characters are still coming back; sort the
        held bytes once the echo of the last one is among them.

        A receiver hands bytes over in wire order, but not one by one: behind a USB latency
        timer, the end of the DUT's previous reply and the echo of the tool's next command
        reach the host in one batch. Taking each byte for an echo or not as it came mistook
        the DUT's late characters for echoes that differed, and then the real echoes for the
        DUT's (issue 18: ``'3!'`` judged as a reply). Held until the last expected character
        is in, the echo is found as the latest bytes that spell what the tool sent, in order:
        whatever came before it left the DUT before the tool spoke, whatever falls between
        its characters is the DUT talking over the tool."""
        self._window.append((byte, end))
        chars = [e for e in self._pending if e.byte is not None]
        if byte != chars[-1].byte:
            return []
        return self._sort_window()

    def _sort_window(self) -> list[Heard]:
        """Sort the held bytes into echoes and the DUT's. An expected character not found
        where it belongs was garbled by a collision if some other byte came in its place (the
        tool sent it all the same), else it stays pending (:meth:`expire` counts it
        missing)."""
        window, self._window = self._window, []
        expected = [e for e in self._pending if e.byte is not None]
        found = _alignment(window, expected)  # index in expected -> position in window
        at = {pos: k for k, pos in found.items()}
        first, last = min(at, default=len(window)), max(at, default=-1)
        garbled: dict[int, int] = {}  # position in window -> index in expected
        lower = -1
        for k in range(len(expected)):
            if k in found:
                lower = found[k]
                continue
            upper = min((found[j] for j in found if j > k), default=len(window))
            free = [p for p in range(lower + 1, upper) if p not in at]
            if free and found:  # some echo came back, and another byte in this one's place
                garbled[free[0]] = k
                lower = free[0]
        talked_over = bool(garbled) or any(
            first < pos < last and pos not in at for pos in range(len(window))
        )
        out: list[Heard] = []
        if found:  # the tool's characters came back: a break's echo is no longer due
            self._owed = None
        for pos, (byte, end) in enumerate(window):
            if pos in at:
                out.append(Heard("tool", byte, end, expected[at[pos]]))
            elif pos in garbled:
                want = expected[garbled[pos]]
                self.collisions += 1
                note = (
                    f"echo differs: the tool sent {_show(want.byte)}, the line carried "
                    f"{_show(byte)} (a collision: the DUT talked over the tool)"
                )
                # the tool's character was sent all the same; what the line carried is the DUT's
                out.append(Heard("tool", want.byte or 0, end, want))
                out.append(Heard("dut", byte, end, note=note, collided=True))
            elif first < pos < last or (pos < first and talked_over):
                # between the echoes, the DUT talked over the tool; before them, in a window
                # that shows it did, the byte may be the tool's own that the echo of the same
                # value (taken as latest) stands for: either way no text of the DUT's
                self.collisions += 1
                note = (
                    f"{_show(byte)} came between the echoes of the tool's own characters "
                    "(a collision: the DUT talked over the tool)"
                )
                out.append(Heard("dut", byte, end, note=note, collided=True))
            else:
                out.append(Heard("dut", byte, end))
        done = set(found) | set(garbled.values())
        self._pending = deque(e for k, e in enumerate(expected) if k not in done)
        return out

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


def _alignment(window: list[tuple[int, float]], expected: list[Expected]) -> dict[int, int]:
    """Where in ``window`` each of ``expected`` came back (its index -> position): the
    latest positions that spell them in order, found from the last one back. Latest, because
    the DUT's bytes that precede an echo left the line before it: the tool's first character
    is the last byte of its value before the second one's echo, and so on. One not found
    before the next one's position is left out (the line garbled or lost it)."""
    out: dict[int, int] = {}
    i = len(window) - 1
    for k in range(len(expected) - 1, -1, -1):
        pos = next((p for p in range(i, -1, -1) if window[p][0] == expected[k].byte), None)
        if pos is not None:
            out[k] = pos
            i = pos - 1
    return out


def _show(byte: int | None) -> str:
    if byte is None:
        return "spacing"
    if 0x20 <= byte < 0x7F:
        return repr(chr(byte))
    return f"0x{byte:02X}"
