"""The sensors the tool plays in the recorder role.

Each played sensor is the reference emulator (:class:`SensorEmulator`) with a profile chosen
to provoke one recorder behaviour (a service request, none, data over D0..D2, 99 concurrent
values, high-volume data past D9...). Some misbehaviour the recorder must cope with (silence
for the first tries, one bad CRC, one garbled reply, an aborted measurement) is not an emulator
fault, so small adapters here wrap the emulator and change what it hears or sends, once. They
are :class:`~conformance.sim.bus.BusDevice` objects like the emulator itself, so the same
sensors serve the virtual-time bus now and a real-time driver later.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..emulator import MeasurementSpec, Profile, SensorEmulator, default_profile
from ..emulator.behaviour import REPLY_DELAY
from ..protocol.commands import CommandError, parse_command
from ..protocol.timing import PARTIAL_COMMAND_GAP, TOLERANCE
from ..protocol.version import V14, format_version
from ..sim.bus import Frame
from ..transcript import to_wire_7e1

#: Marking that separates one transmission from the next as the adapters see them: the
#: partial-command rule (R-AppB-01) makes anything later a new command.
_NEW_TRANSMISSION = PARTIAL_COMMAND_GAP - TOLERANCE
#: A phantom break given to the emulator to abort its measurement (not on the wire).
_PHANTOM_BREAK = 12.5e-3


def _ready(spec: MeasurementSpec, ttt: int, ready_after: float) -> MeasurementSpec:
    return replace(spec, ttt=ttt, ready_after=ready_after)


def played_profile(address: str = "0", version: str = V14) -> Profile:
    """The reference sensor, tuned for judging recorders.

    Data are ready (and the service request of M/V sent) well before half of ttt, so a
    recorder that waits the full ttt, or one that goes early, shows it in the transcript
    without losing the data as a side effect (which would blur what is being judged).
    """
    base = default_profile(version)
    m = dict(base.measurements)
    for key, ttt in (("M", 2), ("M2", 2), ("V", 1), ("C", 2), ("C1", 2), ("C9", 2)):
        if key in m:
            m[key] = _ready(m[key], ttt, 0.25)
    if "C" in m:  # five values: aC! data fit in D0, continuation is judged on M2/C9/HA
        m["C"] = replace(m["C"], values=m["C"].values[:5], metadata=m["C"].metadata[:5])
        m.setdefault("C1", replace(m["C"], values=m["C"].values[:4], metadata=m["C"].metadata[:4]))
    for key in ("HA", "HB"):
        if key in m:
            m[key] = _ready(m[key], 2, 0.25)
    return replace(base, address=address, measurements=m)


class SensorAdapter:
    """Forwards everything to an emulator; subclasses change one thing about it."""

    def __init__(self, inner: SensorEmulator) -> None:
        self.inner = inner
        self.name = inner.name
        self._heard: list[str] = []  # the transmission being heard, as text
        self._heard_end = float("-inf")

    @property
    def address(self) -> str:
        return self.inner.address

    @property
    def profile(self) -> Profile:
        return self.inner.profile

    def on_break(self, start: float, end: float) -> None:
        self._heard = []
        self.inner.on_break(start, end)

    def on_char(self, wire: int, start: float, end: float) -> None:
        if start - self._heard_end >= _NEW_TRANSMISSION or (self._heard and self._heard[-1] == "!"):
            self._heard = []
        self._heard.append(chr(wire & 0x7F))
        self._heard_end = end
        self.inner.on_char(self.hear(wire, len(self._heard) == 1), start, end)
        if self._heard[-1] == "!":
            self.heard_command("".join(self._heard))

    def hear(self, wire: int, first: bool) -> int:
        """What the emulator hears of a character (subclasses may spoil it)."""
        return wire

    def heard_command(self, text: str) -> None:
        """A complete command went by on the line (whoever it was for)."""

    def next_frame(self) -> Frame | None:
        return self.inner.next_frame()

    def pop_frame(self) -> Frame:
        return self.inner.pop_frame()

    def _mine(self, text: str) -> bool:
        return text[:1] == self.address


class Unheard(SensorAdapter):
    """Deaf to the first ``count`` commands addressed to it: a sensor that only answers once
    the recorder has retried (R-7.2-01..04). Their characters reach the emulator with a
    spoiled parity bit, so it sees line activity (and stays awake) but no command."""

    def __init__(self, inner: SensorEmulator, count: int) -> None:
        super().__init__(inner)
        self.remaining = count
        self._muting = False

    def hear(self, wire: int, first: bool) -> int:
        if first:
            self._muting = self.remaining > 0 and chr(wire & 0x7F) == self.address
            if self._muting:
                self.remaining -= 1
        return wire ^ 0x80 if self._muting else wire


@dataclass(frozen=True)
class Spoil:
    """How :class:`Garbled` spoils one reply.

    ``parity``: character ``at`` gets the wrong parity bit. ``crc``: the first digit after the
    address changes, so the CRC no longer matches (R-4.4.12-07). ``format``: character ``at``
    becomes ``?`` (a reply of the wrong shape). ``pause``: ``pause`` s of marking after
    character ``at`` (8.33 ms or more makes the reply invalid, R-7.2-05).
    """

    kind: str
    at: int = 1
    pause: float = 20e-3


class Garbled(SensorAdapter):
    """Spoils its reply to the first ``times`` commands matching ``command`` (exact text)."""

    def __init__(self, inner: SensorEmulator, command: str, spoil: Spoil, times: int = 1) -> None:
        super().__init__(inner)
        self.command = command
        self.spoil = spoil
        self.remaining = times
        self._index: int | None = None  # position in the reply being spoiled
        self._digit_done = False

    def heard_command(self, text: str) -> None:
        if text == self.command and self.remaining > 0:
            self.remaining -= 1
            self._index, self._digit_done = 0, False

    def _change(self, frame: Frame) -> Frame:
        i, s = self._index, self.spoil
        assert i is not None
        char = frame.wire & 0x7F
        if s.kind == "parity" and i == s.at:
            return replace(frame, wire=frame.wire ^ 0x80)
        if s.kind == "format" and i == s.at:
            return replace(frame, wire=to_wire_7e1(ord("?")))
        if s.kind == "crc" and i >= 1 and not self._digit_done and chr(char).isdigit():
            digit = str((int(chr(char)) + 1) % 10)
            return replace(frame, wire=to_wire_7e1(ord(digit)))
        if s.kind == "pause" and i > s.at:
            return replace(frame, start=frame.start + s.pause)
        return frame

    def next_frame(self) -> Frame | None:
        frame = self.inner.next_frame()
        if frame is None or self._index is None:
            return frame
        return self._change(frame)

    def pop_frame(self) -> Frame:
        frame = self.inner.pop_frame()
        if self._index is None:
            return frame
        changed = self._change(frame)
        if changed.wire != frame.wire and self.spoil.kind == "crc":
            self._digit_done = True
        self._index += 1
        if frame.wire & 0x7F == 0x0A:
            self._index = None
        return changed


class AbortsOnce(SensorAdapter):
    """Loses its first measurement (as after a brown-out): right after answering the first
    measurement command it hears, the emulator is given a break nobody sent, which aborts
    that measurement, so the later ``aD0!`` gets the valid empty reply and the recorder has to
    issue the measurement again (R-4.4.8-05)."""

    def __init__(self, inner: SensorEmulator) -> None:
        super().__init__(inner)
        self._armed = False
        self._done = False

    def heard_command(self, text: str) -> None:
        if self._done or not self._mine(text):
            return
        try:
            self._armed = parse_command(text).starts_measurement
        except CommandError:
            return

    def pop_frame(self) -> Frame:
        frame = self.inner.pop_frame()
        if self._armed and frame.wire & 0x7F == 0x0A:
            self._armed, self._done = False, True
            end = frame.start + frame.duration
            self.inner.on_break(end, end + _PHANTOM_BREAK)
        return frame


@dataclass(frozen=True)
class SensorSpec:
    """One sensor a scenario puts on the bus, as data (so scenarios stay declarative).

    ``faults`` are emulator faults; ``unheard`` the number of commands it ignores first;
    ``spoil``/``spoil_command``/``spoil_times`` a reply it garbles; ``aborts_once`` loses the
    first measurement. ``reply_extra`` (s) starts every reply that much later than the
    reference's ~9 ms, ``wake_extra`` (s) is how long after a break's end the sensor needs
    before it hears a start bit at all: the timing knobs of the recorder tolerance sweep
    (:mod:`.sweep`), which go past what the standard allows on purpose.
    """

    address: str = "0"
    faults: tuple[str, ...] = ()
    unheard: int = 0
    spoil: Spoil | None = None
    spoil_command: str = ""
    spoil_times: int = 1
    aborts_once: bool = False
    version: str = V14
    reply_extra: float = 0.0
    wake_extra: float = 0.0
    #: ``(measurement key, ttt, ready_after)`` overrides of :func:`played_profile`'s timing
    #: (a ttt over 255 s, a concurrent ttt = 000...)
    timing: tuple[tuple[str, int, float], ...] = ()

    def describe(self) -> str:
        parts = [f"sensor at {self.address!r} (v{format_version(self.version)})"]
        if self.faults:
            parts.append("faults " + ",".join(self.faults))
        if self.unheard:
            parts.append(f"deaf to its first {self.unheard} command(s)")
        if self.spoil is not None:
            parts.append(f"{self.spoil.kind} error in its reply to {self.spoil_command}")
        if self.aborts_once:
            parts.append("loses its first measurement")
        if self.reply_extra:
            start = (REPLY_DELAY + self.reply_extra) * 1e3
            parts.append(f"starts each reply {start:.2f} ms after the command")
        if self.wake_extra:
            parts.append(f"hears nothing for {self.wake_extra * 1e3:.2f} ms after a break")
        for key, ttt, ready in self.timing:
            parts.append(f"a{key}! announces ttt = {ttt:03d}, data ready after {ready:g} s")
        return ", ".join(parts)

    def quirks(self) -> dict[str, float]:
        """The emulator's timing overrides for ``reply_extra``/``wake_extra`` (none: {})."""
        out: dict[str, float] = {}
        if self.reply_extra:
            out["reply_delay"] = REPLY_DELAY + self.reply_extra
        if self.wake_extra:
            out["wake_delay"] = self.wake_extra
        return out

    def build(self) -> SensorEmulator | SensorAdapter:
        profile = played_profile(self.address, self.version)
        if self.timing:
            m = dict(profile.measurements)
            for key, ttt, ready in self.timing:
                m[key] = _ready(m[key], ttt, ready)
            profile = replace(profile, measurements=m)
        emulator = SensorEmulator(
            profile,
            self.faults,
            name=f"sensor{self.address}",
            quirks=self.quirks() or None,
        )
        device: SensorEmulator | SensorAdapter = emulator
        if self.unheard:
            device = Unheard(emulator, self.unheard)
        elif self.spoil is not None:
            device = Garbled(emulator, self.spoil_command, self.spoil, self.spoil_times)
        elif self.aborts_once:
            device = AbortsOnce(emulator)
        return device


def build_sensors(specs: Sequence[SensorSpec]) -> list[SensorEmulator | SensorAdapter]:
    return [spec.build() for spec in specs]
