"""Receive stamps taken by the kernel, not by a Python thread that may wake late.

On a busy host the reader thread can get the CPU (and the interpreter) milliseconds after a
byte arrived; a stamp taken then is late by that much, and nothing shows it. Linux stamps
every received network packet (``SO_TIMESTAMPNS``); reading those stamps makes a network
link's arrival times independent of when the reader ran, and the difference between the two
stamps is a measurement of how late the reader woke.

pyserial's ``rfc2217://`` and ``socket://`` ports read their socket in pyserial's own code, so
the socket is wrapped (:class:`StampingSocket`) as pyserial assigns it; each ``recv`` becomes
a ``recvmsg`` of one byte with the kernel's stamp. The stamps are kept beside the data bytes
in arrival order (:class:`StampTape`); the link takes as many stamps as bytes it read.
Where the platform gives no stamps (not Linux, a serial device), nothing is wrapped and the
link stamps bytes itself.
"""

from __future__ import annotations

import socket
import struct
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

import serial
from serial import rfc2217
from serial.urlhandler import protocol_socket

from .priority import READER, realtime_priority

SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)  # Linux asm-generic value
STAMP_SPACE = socket.CMSG_SPACE(16) if hasattr(socket, "CMSG_SPACE") else 0


#: A wall-clock read bracketed by two perf_counter reads closer than this (ns) is taken.
TIGHT_BRACKET_NS = 50_000


def bracketed_wall(clock: Callable[[], float], tight: float, tries: int = 4) -> tuple[float, int]:
    """``clock`` and the wall clock (ns) read at one moment: the wall read between two
    ``clock`` reads, from the tightest of up to ``tries`` brackets (one within ``tight``, in
    the clock's units, is taken at once). Read once back to back, a thread descheduled
    between the two reads (a loaded host) pairs readings a whole stall apart."""
    best_width, best = -1.0, (0.0, 0)
    for _ in range(tries):
        before = clock()
        wall = time.time_ns()
        after = clock()
        if best_width < 0 or after - before < best_width:
            best_width, best = after - before, ((before + after) / 2, wall)
        if best_width <= tight:
            break
    return best


def _clock_offset_ns() -> int:
    """CLOCK_REALTIME minus perf_counter (kernel stamps are wall time)."""
    mid, wall = bracketed_wall(time.perf_counter_ns, TIGHT_BRACKET_NS)
    return wall - round(mid)


def recv_stamped_byte(sock: socket.socket, *flags: int) -> tuple[bytes, int | None]:
    """One byte from ``sock`` and the kernel's receive stamp of its packet (wall-clock ns,
    as the kernel gives it; None if none came): the tool's link and the emulator server's
    reader (``emulator_server.servers.ArrivalReader``) both read this way."""
    data, ancdata, _flags, _addr = sock.recvmsg(1, STAMP_SPACE, *flags)
    for level, kind, payload in ancdata:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(payload) >= 16:
            sec, nsec = struct.unpack("qq", payload[:16])
            return data, sec * 1_000_000_000 + nsec
    return data, None


#: Where struct tcp_info (linux/tcp.h) keeps tcpi_data_segs_in, the count of segments with
#: data the connection received (Linux 4.6 and later; a shorter struct has none).
_DATA_SEGS_IN = 152


def data_segments_in(sock: socket.socket) -> int | None:
    """How many segments with data ``sock`` (TCP, Linux) has received so far; None where the
    kernel does not say. The kernel counts a segment and queues it under one socket lock, so
    every segment this counts is in the receive queue (or read) when it returns."""
    try:
        info = sock.getsockopt(socket.IPPROTO_TCP, getattr(socket, "TCP_INFO", -1), 256)
    except OSError:
        return None
    if len(info) < _DATA_SEGS_IN + 4:
        return None
    return int(struct.unpack_from("I", info, _DATA_SEGS_IN)[0])


class StampTape:
    """Kernel stamps (perf_counter ns) of received data bytes, oldest first."""

    def __init__(self) -> None:
        self._stamps: deque[int] = deque()
        self._lock = threading.Lock()

    def add(self, stamp_ns: int, count: int = 1) -> None:
        with self._lock:
            self._stamps.extend([stamp_ns] * count)

    def take(self, count: int) -> list[int] | None:
        """Stamps of the next ``count`` data bytes; None if any is missing (then the link
        stamps the chunk itself)."""
        with self._lock:
            if len(self._stamps) < count:
                self._stamps.clear()
                return None
            return [self._stamps.popleft() for _ in range(count)]


class StampingSocket:
    """A socket whose ``recv`` returns one byte at a time with the kernel's receive stamp
    (the stamp of the packet that byte came in), noted in ``current_ns``; everything else
    is the socket's own."""

    def __init__(self, sock: socket.socket) -> None:
        self._sock = sock
        sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        self.current_ns: int | None = None
        self.on_stamp: Any = None  # called with (stamp_ns, nbytes) for each recv

    def recv(self, _size: int, *flags: int) -> bytes:
        data, wall_ns = recv_stamped_byte(self._sock, *flags)
        stamp = None if wall_ns is None else wall_ns - _clock_offset_ns()
        self.current_ns = stamp
        if self.on_stamp is not None and data:
            self.on_stamp(stamp, len(data))
        return data

    def __getattr__(self, name: str) -> Any:
        return getattr(self._sock, name)


class _TapedQueue:
    """pyserial's rfc2217 read buffer (a queue of single data bytes), with each byte's
    kernel stamp put on the tape as the byte is queued (the reader thread does both)."""

    def __init__(self, inner: Any, owner: StampedRfc2217Serial) -> None:
        self._inner = inner
        self._owner = owner

    def put(self, item: Any, *args: Any, **kwargs: Any) -> None:
        sock = self._owner._stamping
        if item is not None and sock is not None:
            stamp = sock.current_ns
            if stamp is None:
                stamp = time.perf_counter_ns()
            self._owner.kernel_stamps.add(stamp, len(item))
        self._inner.put(item, *args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)


class StampedRfc2217Serial(rfc2217.Serial):
    """pyserial's RFC 2217 client with kernel receive stamps (``kernel_stamps``)."""

    realtime_priority = False  # the telnet reader thread got a real-time class

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.kernel_stamps = StampTape()
        self._stamping: StampingSocket | None = None
        self._sock_value: Any = None
        self._queue_value: Any = None
        super().__init__(*args, **kwargs)

    def _telnet_read_loop(self) -> None:
        """pyserial's reader, on a thread that other work on the machine cannot starve: a
        late reader lets the kernel merge packets, and merged packets share one stamp."""
        self.realtime_priority = realtime_priority(READER)
        super()._telnet_read_loop()

    @property  # type: ignore[override]
    def _socket(self) -> Any:
        return self._sock_value

    @_socket.setter
    def _socket(self, value: Any) -> None:
        if isinstance(value, socket.socket) and sys.platform.startswith("linux"):
            value = StampingSocket(value)
            self._stamping = value
        self._sock_value = value

    @property
    def _read_buffer(self) -> Any:
        return self._queue_value

    @_read_buffer.setter
    def _read_buffer(self, value: Any) -> None:
        self._queue_value = value if value is None else _TapedQueue(value, self)


class StampedSocketSerial(protocol_socket.Serial):
    """pyserial's raw ``socket://`` port with kernel receive stamps (``kernel_stamps``)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.kernel_stamps = StampTape()
        self._sock_value: Any = None
        super().__init__(*args, **kwargs)

    @property  # type: ignore[override]
    def _socket(self) -> Any:
        return self._sock_value

    @_socket.setter
    def _socket(self, value: Any) -> None:
        if isinstance(value, socket.socket) and sys.platform.startswith("linux"):
            value = StampingSocket(value)
            value.on_stamp = self._stamped
        self._sock_value = value

    def _stamped(self, stamp: int | None, count: int) -> None:
        self.kernel_stamps.add(stamp if stamp is not None else time.perf_counter_ns(), count)


def stamped_port(url: str, **settings: Any) -> serial.SerialBase:
    """An unopened pyserial port for ``url`` that keeps kernel stamps where it can."""
    scheme = url.split("://", 1)[0].lower() if "://" in url else ""
    cls = {"rfc2217": StampedRfc2217Serial, "socket": StampedSocketSerial}.get(scheme)
    if cls is None:
        return serial.serial_for_url(url, do_not_open=True, **settings)
    port = cls(None, **settings)
    port.port = url
    return port
