"""A link through a transparent USB SDI-12 adapter: command lines out, response lines back.

Such an adapter takes ``0M!`` (plus a terminator, usually CR) from the host at its own baud
rate, makes the break, the marking and the 1200-baud 7E1 framing itself, and sends back what
the sensor answered, as a line. The host never sees the bus: no breaks of its own, no
character timing, usually no service requests and no 8N1 binary packets. Protocol-level cases
can still be judged; the rest is declared in :class:`LinkInfo` so the plugin makes those
cases INCONCLUSIVE with the reason instead of judging the adapter's timing as the sensor's.

Port strings (options in the query, the rest passed on to pyserial)::

    adapter:///dev/ttyUSB0?baud=9600          a local adapter
    adapter:COM3                              likewise on Windows
    adapter+socket://127.0.0.1:4001           an adapter (or a fake) behind TCP
    adapter+rfc2217://host:port               ... behind an RFC 2217 server

Options: ``baud`` (default 9600), ``eol`` (``cr``, ``crlf``, ``lf`` or ``none``; default
``cr``), ``timeout`` (s to wait for a response line after a command, default 1.0: the
adapter returns a line only once the sensor finished it, up to ~700 ms for a long D reply),
``wake`` (ms the adapter spends on its own break and marking before the command, default
20.33, where the command's characters are stamped).

Stamps are estimates with a declared 50 ms uncertainty, which is what makes the judges'
uncertainty rule turn timing verdicts INCONCLUSIVE here rather than PASS or FAIL.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from urllib.parse import parse_qs, urlencode, urlsplit, urlunsplit

import serial

from ..protocol.timing import BREAK_MIN, CHAR_TIME, MARKING_AFTER_BREAK
from ..transcript import DUT, Event, EventKind, to_wire_7e1
from .base import LinkInfo, StopCondition
from .errors import PortUnavailable, unavailable
from .registry import LinkKind, OpenedPort, PortOptions, register
from .serial_link import READ_POLL, SerialLink, precise_sleep_until
from .stamps import chunk_frames

PREFIX = "adapter"
ADAPTER_UNCERTAINTY = 50e-3  # s: USB batching plus the adapter's own unknown turnaround
DEFAULT_BAUD = 9600
DEFAULT_TIMEOUT = 1.0
DEFAULT_WAKE = BREAK_MIN + MARKING_AFTER_BREAK  # s: the adapter's break plus the marking after it
LINE_IDLE = 0.1  # s: a partial line quiet this long is handed over without its LF
MAX_LINE = 1100  # bytes: a line that never ends is handed over in pieces this long
TERMINATORS = {"cr": b"\r", "crlf": b"\r\n", "lf": b"\n", "none": b""}
OPEN_TIMEOUT = 5.0
#: What a link through an adapter can do: no breaks of its own, no unsolicited bytes, no 8N1
#: packets, stamps good to 50 ms.
INFO = LinkInfo(
    kind="adapter",
    can_break=False,
    passes_unsolicited=False,
    binary=False,
    timing_uncertainty=ADAPTER_UNCERTAINTY,
)


def is_adapter_port(port: str) -> bool:
    """True for ``adapter:...`` and ``adapter+scheme://...`` port strings."""
    low = port.lower()
    return low.startswith(PREFIX + ":") or low.startswith(PREFIX + "+")


@dataclass(frozen=True)
class AdapterSpec:
    """A parsed ``adapter`` port string: the pyserial URL behind it and the options."""

    url: str
    baud: int = DEFAULT_BAUD
    eol: bytes = b"\r"
    timeout: float = DEFAULT_TIMEOUT
    wake: float = DEFAULT_WAKE


def parse_adapter_port(port: str) -> AdapterSpec:
    """Split ``port`` into the inner pyserial URL and our options; ValueError if malformed."""
    if not is_adapter_port(port):
        raise ValueError(f"not an adapter port: {port!r}")
    rest = port[len(PREFIX) :]
    if rest.startswith("+"):
        inner = rest[1:]
    else:
        inner = rest[1:]  # after "adapter:"
        inner = inner[2:] if inner.startswith("//") else inner  # adapter:///dev/x -> /dev/x
    parts = urlsplit(inner) if "://" in inner else None
    query = parts.query if parts else (inner.split("?", 1)[1] if "?" in inner else "")
    options = parse_qs(query, keep_blank_values=True)
    mine = {k: options.pop(k)[-1] for k in ("baud", "eol", "timeout", "wake") if k in options}
    if parts:
        url = urlunsplit(parts._replace(query=urlencode(options, doseq=True)))
    else:
        url = inner.split("?", 1)[0]
        if options:
            raise ValueError(f"unknown adapter option(s): {', '.join(sorted(options))}")
    if not url:
        raise ValueError(f"no device in adapter port {port!r}")
    eol = mine.get("eol", "cr").lower()
    if eol not in TERMINATORS:
        raise ValueError(f"eol must be one of {', '.join(TERMINATORS)}, not {eol!r}")
    spec = AdapterSpec(
        url=url,
        baud=int(mine.get("baud", DEFAULT_BAUD)),
        eol=TERMINATORS[eol],
        timeout=float(mine.get("timeout", DEFAULT_TIMEOUT)),
        wake=float(mine["wake"]) / 1e3 if "wake" in mine else DEFAULT_WAKE,
    )
    if spec.baud <= 0 or spec.timeout <= 0 or spec.wake < 0:
        raise ValueError(f"baud and timeout must be positive, wake not negative: {port!r}")
    return spec


class AdapterLink(SerialLink):
    """The tool's end of a bus reached through a transparent SDI-12 adapter.

    Built on :class:`SerialLink` for the reader thread, failure handling and ``send_break``
    (which, with no break maker, notes the missing break and raises ``BreakUnsupported``).
    What differs: commands go out as text lines, and received bytes are gathered into lines
    before they are stamped, because an adapter hands over a line at once and stamping its
    pieces separately would make frames overlap that never did on the bus.
    """

    def __init__(
        self,
        port: serial.SerialBase,
        spec: AdapterSpec,
        *,
        timing_uncertainty: float | None = None,
        name: str = "",
    ) -> None:
        self.spec = spec
        self._line = bytearray()  # bytes of the line being received, not yet events
        self._line_arrival = 0.0
        self._pending_until: float | None = None  # a command awaits its response line
        info = replace(
            INFO,
            timing_uncertainty=(
                ADAPTER_UNCERTAINTY if timing_uncertainty is None else timing_uncertainty
            ),
        )
        super().__init__(port, info, None, name=name)

    # -- receiving: whole lines, stamped at the arrival of their last byte ----------------------
    def _arrived(self, data: bytes, arrival: float) -> None:
        with self._cond:
            for byte in data:
                self._line.append(byte)
                if byte == 0x0A or len(self._line) >= MAX_LINE:
                    self._flush_line(arrival)
            self._line_arrival = arrival
            self._cond.notify_all()

    def _flush_line(self, arrival: float) -> None:
        """Turn the gathered line into DUT events (caller holds the lock)."""
        if not self._line:
            return
        frames = chunk_frames(len(self._line), arrival, self._rx_floor)
        for byte, (start, end) in zip(self._line, frames, strict=True):
            event = Event(
                EventKind.CHAR,
                DUT,
                start,
                end,
                wire=to_wire_7e1(byte),
                uncertainty=self.info.timing_uncertainty,
            )
            self.transcript.add(event)
            self._rx.append(event)
        self._rx_floor = frames[-1][1]
        self._line.clear()
        self._pending_until = None  # the command got its answer

    def _flush_if_idle(self) -> None:
        if self._line and self.now() - self._line_arrival >= LINE_IDLE:
            self._flush_line(self._line_arrival)

    # -- sending: the command as a text line --------------------------------------------------
    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        """Send ``wire`` (one command, 7E1 frames) as text plus the adapter's terminator.

        The adapter paces the characters itself, so ``gap`` cannot be honoured; the events
        place the characters where the adapter will put them: after its own wake-up break,
        back to back at 1200 baud. Returns once the last of them would be on the bus."""
        self._check()
        if not wire:
            return []
        text = bytes(b & 0x7F for b in wire)
        with self._cond:
            self._flush_if_idle()
            if gap > 0:
                self.transcript.note(
                    self.now(), f"gap of {gap * 1e3:.2f} ms not sent: the adapter paces the line"
                )
        start = max(self.now(), self._tx_free) + self.spec.wake
        self._port_write(text + self.spec.eol)
        events = [self._tool_char(byte, start + k * CHAR_TIME) for k, byte in enumerate(wire)]
        with self._cond:
            self._pending_until = events[-1].end + self.spec.timeout
        precise_sleep_until(self.now, events[-1].end)
        return events

    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        """As :meth:`SerialLink.receive`, except that after a command it first waits (up to
        the ``timeout`` option) for the response line: the adapter holds it back until the
        sensor has finished it, long after the bus deadline the caller computed."""
        with self._cond:
            while True:
                self._flush_if_idle()
                pending = self._pending_until
                if self._rx or pending is None or self.now() >= pending:
                    break
                self._check()
                self._cond.wait(min(pending - self.now(), READ_POLL))
            if self._pending_until is not None and self.now() >= self._pending_until:
                self._pending_until = None  # no answer: do not wait again for this command
        return super().receive(deadline, until, idle)


def open_adapter_link(port: str, timing_uncertainty: float | None = None) -> AdapterLink:
    """Open an ``adapter`` port string (see the module docstring) as an :class:`AdapterLink`."""
    try:
        spec = parse_adapter_port(port)
    except ValueError as exc:
        raise PortUnavailable(f"bad adapter port {port!r}: {exc}") from exc
    try:
        raw = serial.serial_for_url(
            spec.url,
            baudrate=spec.baud,
            bytesize=serial.EIGHTBITS,
            parity=serial.PARITY_NONE,
            stopbits=serial.STOPBITS_ONE,
            timeout=READ_POLL,
            write_timeout=OPEN_TIMEOUT,
            do_not_open=True,
        )
        raw.open()
    except (serial.SerialException, OSError, ValueError, NotImplementedError) as exc:
        inner = spec.url.split("://", 1)[0].lower() if "://" in spec.url else "serial"
        raise unavailable(spec.url, inner, exc) from exc
    return AdapterLink(raw, spec, timing_uncertainty=timing_uncertainty, name=port)


def _open_kind(port: str, options: PortOptions) -> OpenedPort:
    options.modes()  # an unknown --echo/--direction is refused here too, though unused
    return OpenedPort(open_adapter_link(port, options.timing_uncertainty))


KIND = register(
    LinkKind(
        "adapter",
        matches=is_adapter_port,
        open_sensor_role=_open_kind,
        info=INFO,
        example="adapter:///dev/ttyUSB0?baud=9600",
    )
)
