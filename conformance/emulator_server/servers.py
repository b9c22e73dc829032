"""Put an emulated line where a recorder can reach it: a TCP port (RFC 2217 or raw bytes) or a
real serial port.

RFC 2217 is served through pyserial's :class:`serial.rfc2217.PortManager` (telnet options,
port settings, SET_CONTROL) over a :class:`VirtualPort` whose ``break_condition`` is the
emulated line's spacing. Raw TCP (what ``socket://`` speaks) carries bytes only, so a
recorder on it can never wake the sensor with a break. On a real serial port a break arrives
as a NUL byte with a framing error (no SDI-12 command contains NUL), so a NUL is taken as a
break that ended when it was read.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable

import serial
from serial import rfc2217

from ..links.stamps import chunk_frames
from ..protocol.timing import BREAK_MIN, CHAR_TIME
from .realtime import RealTimeLine

RECV_POLL = 0.1  # s: socket and port reads time out this often so a stop is noticed


class VirtualPort:
    """What :class:`serial.rfc2217.PortManager` needs of a serial port, for an emulated line:
    settings it may read and write, quiet modem lines, and ``break_condition``."""

    def __init__(self, line: RealTimeLine) -> None:
        self.line = line
        self.arrival: float | None = None  # when the bytes being filtered reached the server
        self.baudrate = 1200
        self.bytesize = serial.EIGHTBITS
        self.parity = serial.PARITY_NONE
        self.stopbits = serial.STOPBITS_ONE
        self.xonxoff = False
        self.rtscts = False
        self.dtr = True
        self._rts = not line.bench.require_rts
        self.cts = self.dsr = self.ri = self.cd = False
        self._break = False

    @property
    def rts(self) -> bool:
        return self._rts

    @rts.setter
    def rts(self, value: bool) -> None:
        """The recorder's transmit enable (an RS-485-style driver on an RTS line)."""
        self._rts = bool(value)
        self.line.set_rts(self._rts)

    @property
    def break_condition(self) -> bool:
        return self._break

    @break_condition.setter
    def break_condition(self, value: bool) -> None:
        self._break = bool(value)
        if value:
            self.line.break_on(self.arrival)
        else:
            self.line.break_off(self.arrival)

    def reset_input_buffer(self) -> None:
        """Nothing is buffered: bytes go on the emulated wire as they arrive."""

    def reset_output_buffer(self) -> None:
        """Nothing is buffered: the device's frames leave when their time comes."""


class _Connection:
    """A thread-safe ``write`` for the PortManager and the line (both answer on one socket)."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.lock = threading.Lock()

    def write(self, data: bytes) -> None:
        with self.lock:
            self.sock.sendall(data)


def _discard(_data: bytes) -> None:
    """Where the device's output goes while no recorder is connected."""


class TcpEmulatorServer:
    """Serve one emulated line on a TCP port, one recorder connection at a time. The device
    keeps its state between connections, as a sensor on a bus would."""

    def __init__(
        self,
        line: RealTimeLine,
        host: str,
        port: int,
        *,
        rfc2217_protocol: bool = True,
        log: Callable[[str], None] = lambda _msg: None,
    ) -> None:
        self.line = line
        self.rfc2217 = rfc2217_protocol
        self.log = log
        self.listener = socket.create_server((host, port))
        self.listener.settimeout(RECV_POLL)
        self.address = self.listener.getsockname()[:2]
        self.stopped = threading.Event()
        self.connections = 0

    @property
    def url(self) -> str:
        scheme = "rfc2217" if self.rfc2217 else "socket"
        return f"{scheme}://{self.address[0]}:{self.address[1]}"

    def serve(self, once: bool = False) -> None:
        """Accept recorders until :meth:`stop` (or, with ``once``, after the first leaves)."""
        try:
            while not self.stopped.is_set():
                try:
                    sock, peer = self.listener.accept()
                except TimeoutError:
                    continue
                self.connections += 1
                self.log(f"recorder connected from {peer[0]}:{peer[1]}")
                since = self.line.mark()
                try:
                    self._serve_connection(sock)
                finally:
                    sock.close()
                    kept = self.line.timekeeping(since, "this connection")
                    self.log(f"recorder disconnected; {kept}")
                if once:
                    return
        finally:
            self.listener.close()

    def stop(self) -> None:
        self.stopped.set()

    def _serve_connection(self, sock: socket.socket) -> None:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.settimeout(RECV_POLL)
        conn = _Connection(sock)
        port = VirtualPort(self.line)
        if self.rfc2217:
            manager = rfc2217.PortManager(port, conn)
            self.line.set_sender(lambda data: conn.write(b"".join(manager.escape(data))))
        else:
            self.line.set_sender(conn.write)
        try:
            while not self.stopped.is_set():
                try:
                    data = sock.recv(4096)
                except TimeoutError:
                    continue
                except OSError:
                    return
                if not data:
                    return
                at = self.line.now()
                if not self.rfc2217:
                    self.line.tool_bytes(data, at)
                    continue
                port.arrival = at
                # byte by byte: a SET_CONTROL inside the chunk toggles the break in between
                for byte in manager.filter(data):
                    self.line.tool_bytes(byte, at, port.baudrate)
        finally:
            self.line.set_sender(_discard)
            if port.break_condition:
                port.break_condition = False


def serve_serial(line: RealTimeLine, port: serial.SerialBase, stopped: threading.Event) -> None:
    """Feed what a real serial port receives into ``line`` until ``stopped`` is set.

    Bytes are stamped on arrival and laid back to back ending then (chunks read at once
    cannot show their gaps); a NUL is a break of at least 12 ms that ended as it was read.
    """
    floor = 0.0
    while not stopped.is_set():
        data = port.read(max(1, port.in_waiting))
        if not data:
            continue
        at = line.now()
        frames = chunk_frames(len(data), at, floor)
        floor = frames[-1][1]
        for byte, (start, end) in zip(data, frames, strict=True):
            if byte == 0:
                line.break_on(end - max(BREAK_MIN, CHAR_TIME))
                line.break_off(end)
            else:
                line.tool_bytes(bytes([byte]), start)
