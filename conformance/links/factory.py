"""Open a real link from a ``--port`` string: a device path or any pyserial URL.

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

import errno
from urllib.parse import urlsplit

import serial

from .base import Link, LinkInfo
from .breaks import BaudPulse, BreakMaker, Rfc2217Break, UartBreak
from .direction import Direction, DirectionLine
from .echo import EchoMode
from .errors import PortUnavailable
from .kernel_stamps import stamped_port
from .serial_link import READ_POLL, SerialLink

BAUD = 1200
LOCAL_NET_UNCERTAINTY = 5e-3
REMOTE_NET_UNCERTAINTY = 10e-3
LOOP_UNCERTAINTY = 1e-3
LOW_LATENCY_UNCERTAINTY = 2e-3
USB_UNCERTAINTY = 16e-3
OPEN_TIMEOUT = 5.0  # s: an rfc2217/socket server that does not answer is a usage error
LOOPBACK_HOSTS = ("127.", "localhost", "::1", "[::1]")


def port_kind(port: str) -> str:
    scheme = port.split("://", 1)[0].lower() if "://" in port else ""
    return {"rfc2217": "rfc2217", "socket": "socket", "loop": "loop"}.get(scheme, "serial")


def _is_loopback(port: str) -> bool:
    host = urlsplit(port).hostname or ""
    return host.startswith(LOOPBACK_HOSTS) or host in LOOPBACK_HOSTS


def open_real_link(
    port: str,
    timing_uncertainty: float | None = None,
    *,
    echo: EchoMode = EchoMode.AUTO,
    direction: DirectionLine = DirectionLine.NONE,
) -> Link:
    """Open ``port`` at 1200 baud 8N1 (parity in software) and wrap it in a link.

    ``timing_uncertainty`` (s) only widens what the link measures; it never narrows it."""
    from .adapter_link import is_adapter_port, open_adapter_link

    if is_adapter_port(port):
        return open_adapter_link(port, timing_uncertainty)
    kind = port_kind(port)
    raw = _open(port, kind, direction)
    breaker: BreakMaker | None = None
    pulse: BaudPulse | None = None
    if kind == "rfc2217" or (kind == "serial" and not _is_pty(port)):
        pulse = BaudPulse(raw)  # a pseudo-terminal has no bit clock: its NUL is just a byte
    if kind == "serial":
        breaker = UartBreak(raw)
        uncertainty = USB_UNCERTAINTY
        if _low_latency(raw):
            uncertainty = LOW_LATENCY_UNCERTAINTY
    elif kind == "loop":
        uncertainty = LOOP_UNCERTAINTY
    else:
        if kind == "rfc2217":
            breaker = Rfc2217Break(raw)
        uncertainty = LOCAL_NET_UNCERTAINTY if _is_loopback(port) else REMOTE_NET_UNCERTAINTY
    info = LinkInfo(kind=kind, can_break=breaker is not None, timing_uncertainty=uncertainty)
    link = SerialLink(
        raw,
        info,
        breaker,
        name=port,
        echo=echo,
        pulse=pulse,
        direction=None if direction is DirectionLine.NONE else Direction(raw, direction),
    )
    if timing_uncertainty is not None:
        link.meter.widen_to = timing_uncertainty
    return link


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
        raise PortUnavailable(_explain(port, kind, exc)) from exc
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


def _explain(port: str, kind: str, exc: BaseException) -> str:
    """One message that says what went wrong and what to try."""
    code = getattr(exc, "errno", None)
    text = str(exc)
    if kind in ("rfc2217", "socket"):
        return (
            f"cannot connect to {port}: {text}. Is the server running and listening there "
            "(for the emulator: sdi12-conform emulate --listen HOST:PORT)?"
        )
    if code == errno.ENOENT or "No such file" in text or "FileNotFoundError" in text:
        return (
            f"serial port {port} does not exist. Check the cable and the device name "
            "(Linux: ls /dev/ttyUSB* /dev/ttyACM*; Windows: COMn in Device Manager), "
            "or run against the built-in simulated sensor with --port sim"
        )
    if code == errno.EACCES or "Permission denied" in text:
        return (
            f"permission denied on serial port {port}. Add your user to the group that owns "
            "it (Linux: sudo usermod -aG dialout $USER, then log in again)"
        )
    if code == errno.EBUSY or "busy" in text.lower():
        return f"serial port {port} is busy: close the other program using it"
    return f"cannot open port {port}: {text}"
