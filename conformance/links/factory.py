"""The link kinds pyserial opens: a device path or any pyserial URL, each registered with
:mod:`~conformance.links.registry` (the adapter kind is :mod:`~conformance.links.adapter_link`).

What each kind can do, and how far its stamps can be trusted, is decided here once:

- a device path (``/dev/ttyUSB0``, ``COM3``) or another pyserial URL: kind ``serial``,
  breaks through ``break_condition``; 2 ms when the driver accepts low-latency mode, else
  16 ms (a USB adapter's latency timer may hold bytes that long);
- ``rfc2217://host:port``: breaks through raw SET_CONTROL; 5 ms on loopback (the far end is
  usually another process on a shared machine: its scheduling delays of a few ms, and
  ours, land on the stamps), 10 ms across a network;
- ``socket://host:port``: no breaks; uncertainty as for rfc2217;
- ``loop://``: no breaks, 1 ms;
- ``adapter:...`` / ``adapter+URL``: a transparent SDI-12 adapter
  (:mod:`~conformance.links.adapter_link`): no breaks, no unsolicited bytes, 50 ms.

These figures are floors: the link measures what its stamps are worth as the run goes
(:mod:`~conformance.links.meter`), and ``--timing-uncertainty-ms`` may only widen the result.
With ``--echo auto`` (the default) the link finds out on its first transmission whether the
interface echoes the tool's characters; ``--direction rts|dtr`` raises that line for the tool's
transmissions. Where the port can change its bit rate (a local UART, RFC 2217), breaks and
short spacing pulses are NULs at a lower rate, timed by the UART.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from urllib.parse import urlsplit

import serial

from ..protocol.timing import BAUD
from . import adapter_link
from .base import Link, LinkInfo
from .breaks import BaudPulse, BreakMaker, Rfc2217Break, UartBreak
from .driver_enable import Direction, DirectionLine
from .echo import EchoMode
from .errors import PortError, unavailable
from .kernel_stamps import stamped_port
from .registry import LinkKind, OpenedPort, Opener, PortOptions, find, register, scheme_is
from .serial_link import READ_POLL, SerialLink

LOCAL_NET_UNCERTAINTY = 5e-3
REMOTE_NET_UNCERTAINTY = 10e-3
LOOP_UNCERTAINTY = 1e-3
LOW_LATENCY_UNCERTAINTY = 2e-3
USB_UNCERTAINTY = 16e-3
OPEN_TIMEOUT = 5.0  # s: an rfc2217/socket server that does not answer is a usage error
LOOPBACK_HOSTS = ("127.", "localhost", "::1", "[::1]")

#: What a kind's port adds to the raw pyserial port: its break maker, its bit-clock pulse
#: maker, and the uncertainty floor of its stamps.
LineSetup = Callable[[serial.SerialBase, str], tuple[BreakMaker | None, BaudPulse | None, float]]


def port_kind(port: str) -> str:
    """The registered kind ``port`` names (``serial`` for a device name)."""
    return find(port).name


def _is_loopback(port: str) -> bool:
    host = urlsplit(port).hostname or ""
    return host.startswith(LOOPBACK_HOSTS) or host in LOOPBACK_HOSTS


def _net_uncertainty(port: str) -> float:
    return LOCAL_NET_UNCERTAINTY if _is_loopback(port) else REMOTE_NET_UNCERTAINTY


def _serial_line(raw: serial.SerialBase, port: str):
    # a pseudo-terminal has no bit clock: its NUL is just a byte
    pulse = None if _is_pty(port) else BaudPulse(raw)
    breaker = UartBreak(raw)
    return breaker, pulse, LOW_LATENCY_UNCERTAINTY if _low_latency(raw) else USB_UNCERTAINTY


def _rfc2217_line(raw: serial.SerialBase, port: str):
    return Rfc2217Break(raw), BaudPulse(raw), _net_uncertainty(port)


def _socket_line(raw: serial.SerialBase, port: str):
    return None, None, _net_uncertainty(port)


def _loop_line(raw: serial.SerialBase, port: str):
    return None, None, LOOP_UNCERTAINTY


def open_real_link(
    port: str,
    timing_uncertainty: float | None = None,
    *,
    echo: EchoMode = EchoMode.AUTO,
    direction: DirectionLine = DirectionLine.NONE,
) -> Link:
    """Open ``port`` at 1200 baud 8N1 (parity in software) and wrap it in a link.

    ``timing_uncertainty`` (s) only widens what the link measures; it never narrows it. A
    port string of a virtual-time kind (``sim``, ``exec:``) is taken as a device name here."""
    kind = find(port)
    if kind.info.virtual_time:
        kind = SERIAL
    options = PortOptions(echo.value, direction.value, timing_uncertainty)
    assert kind.open_sensor_role is not None  # a real interface: the tool transmits on it
    return kind.open_sensor_role(port, options).link


def _pyserial_opener(info: LinkInfo, setup: LineSetup) -> Opener:
    def open_kind(port: str, options: PortOptions) -> OpenedPort:
        check_network_url(port)
        echo, direction = options.modes()
        return OpenedPort(
            _open_link(port, info, setup, options.timing_uncertainty, echo, direction)
        )

    return open_kind


def _open_link(
    port: str,
    kind: LinkInfo,
    setup: LineSetup,
    timing_uncertainty: float | None,
    echo: EchoMode,
    direction: DirectionLine,
) -> Link:
    raw = _open(port, kind.kind, direction)
    breaker, pulse, uncertainty = setup(raw, port)
    info = replace(kind, can_break=breaker is not None, timing_uncertainty=uncertainty)
    link = SerialLink(
        raw,
        info,
        breaker,
        name=port,
        echo=echo,
        pulse=pulse,
        direction=None if direction is DirectionLine.NONE else Direction(raw, direction),
    )
    link.widen(timing_uncertainty)
    return link


def check_network_url(port: str) -> None:
    """``rfc2217://`` / ``socket://`` need HOST:PORT; pyserial's own complaint about a
    missing one is a TypeError from deep inside it."""
    scheme = port.split("://", 1)[0].lower() if "://" in port else ""
    if scheme not in ("rfc2217", "socket"):
        return
    parts = urlsplit(port)
    try:
        number = parts.port
    except ValueError:
        number = None
    if not parts.hostname or number is None:
        raise PortError(
            f"port {port!r}: write {scheme}://HOST:PORT, e.g. {scheme}://127.0.0.1:4001"
        )


def _open(port: str, kind: str, direction: DirectionLine = DirectionLine.NONE) -> serial.SerialBase:
    try:
        raw = stamped_port(
            port,
            baudrate=BAUD,
            bytesize=serial.EIGHTBITS,
            parity=serial.PARITY_NONE,
            stopbits=serial.STOPBITS_ONE,
            timeout=READ_POLL,
        )
        if kind == "serial":
            raw.write_timeout = OPEN_TIMEOUT  # a stuck UART must not block a write forever
        if direction is DirectionLine.RTS:
            raw.rts = False  # the driver stays off until the tool transmits
        elif direction is DirectionLine.DTR:
            raw.dtr = False
        raw.open()
    except (serial.SerialException, OSError, ValueError, NotImplementedError) as exc:
        raise unavailable(port, kind, exc) from exc
    return raw


def _is_pty(port: str) -> bool:
    """A pseudo-terminal (emulators, socat): bytes without line timing or breaks."""
    return port.startswith(("/dev/pts/", "/dev/ptmx", "/dev/tty.pty")) or "/pty" in port


def _low_latency(raw: serial.SerialBase) -> bool:
    """Ask the driver to hand bytes over at once (Linux ASYNC_LOW_LATENCY; FTDI adapters
    otherwise hold them up to 16 ms). False where the platform or driver refuses."""
    setter = getattr(raw, "set_low_latency_mode", None)
    if setter is None:
        return False
    try:
        setter(True)
    except (ValueError, OSError, NotImplementedError):
        return False
    return True


def _kind(
    name: str, setup: LineSetup, info: LinkInfo, example: str, *, fallback: bool = False
) -> LinkKind:
    return LinkKind(
        name,
        matches=scheme_is(name),
        open_sensor_role=_pyserial_opener(info, setup),
        info=info,
        example=example,
        fallback=fallback,
    )


_PYSERIAL = tuple(
    register(kind)
    for kind in (
        _kind(
            "rfc2217",
            _rfc2217_line,
            LinkInfo("rfc2217", timing_uncertainty=REMOTE_NET_UNCERTAINTY),
            "rfc2217://127.0.0.1:4001",
        ),
        _kind(
            "socket",
            _socket_line,
            LinkInfo("socket", can_break=False, timing_uncertainty=REMOTE_NET_UNCERTAINTY),
            "socket://127.0.0.1:4001",
        ),
        _kind(
            "loop",
            _loop_line,
            LinkInfo("loop", can_break=False, timing_uncertainty=LOOP_UNCERTAINTY),
            "loop://",
        ),
        # a device name, or any other pyserial URL (spy://, hwgrep://, alt://)
        _kind(
            "serial",
            _serial_line,
            LinkInfo("serial", timing_uncertainty=USB_UNCERTAINTY),
            "/dev/ttyUSB0",
            fallback=True,
        ),
    )
)
RFC2217, SOCKET, LOOP, SERIAL = _PYSERIAL
ADAPTER = adapter_link.KIND  # registered by its own module, opened through pyserial too
