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

import itertools
import select
import socket
import sys
import threading
from collections.abc import Callable

import serial
from serial import rfc2217

from ..links.kernel_stamps import (
    SO_TIMESTAMPNS,
    STAMP_SPACE,
    TIGHT_BRACKET_NS,
    bracketed_wall,
    data_segments_in,
    recv_stamped_byte,
)
from ..links.stamps import chunk_frames
from ..protocol.timing import BREAK_MIN, CHAR_TIME
from .arrivals import Arrival, ToolEvent, lay, step
from .realtime import RealTimeLine

RECV_POLL = 0.1  # s: socket and port reads time out this often so a stop is noticed
#: How often (s) a served line's reader looks at an idle socket and notes it empty: what
#: arrives next came after that (ArrivalReader.empty_at), which bounds how long bytes read
#: together may have lain merged in the kernel (arrivals.char_doubt). One look costs some
#: 10 us of CPU: 1 ms keeps the doubt of a prompt read near 1 ms for about 1 % of a core.
EMPTY_POLL = 1e-3
#: How long (s) after the recorder's last arrival the reader keeps looking every
#: :data:`EMPTY_POLL` where it can count segments (ArrivalReader): inside an exchange a look
#: is what bounds a merged packet's span; on a line idle longer it blocks up to
#: :data:`RECV_POLL` instead (3 % of a core per idle line for looks that bound nothing).
ACTIVE_WINDOW = 1.0


class VirtualPort:
    """What :class:`serial.rfc2217.PortManager` needs of a serial port, for an emulated line:
    settings it may read and write, quiet modem lines, and ``break_condition``."""

    def __init__(self, line: RealTimeLine) -> None:
        self.line = line
        # what the recorder did, in order, while the PortManager filters one arrival: the
        # server lays it on the line once the arrival's events are all known (arrivals.lay)
        self.events: list[ToolEvent] = []
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
        self.events.append(ToolEvent("rts", on=self._rts))

    @property
    def break_condition(self) -> bool:
        return self._break

    @break_condition.setter
    def break_condition(self, value: bool) -> None:
        if bool(value) != self._break:
            self.events.append(ToolEvent("break", on=bool(value)))
        self._break = bool(value)

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
        # from now on: the kernel stamps a packet as it is received, and only if asked by
        # then (a connection's first bytes may come before its reader starts)
        ArrivalReader.ask_for_stamps(self.listener)
        self.address = self.listener.getsockname()[:2]
        self.stopped = threading.Event()
        self.connections = 0
        # nothing a recorder sends can have arrived before the server listened: the floor of
        # a connection's first arrival (:class:`ArrivalReader`), however late it was accepted
        self.opened = line.now()

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
        reader = ArrivalReader(sock, self.line.now, self.opened)
        try:
            while not self.stopped.is_set():
                try:
                    groups = reader.read()
                except TimeoutError:
                    continue
                except OSError:
                    return
                if groups is None:
                    return
                for data, since, at, stamped in groups:
                    earliest = reader.empty_at
                    if self.rfc2217:
                        # byte by byte: a SET_CONTROL inside the data switches in between
                        for byte in manager.filter(data):
                            port.events.append(ToolEvent("bytes", byte, port.baudrate))
                        events, port.events = tuple(port.events), []
                    else:
                        events = (ToolEvent("bytes", data),)
                    lay(self.line, Arrival(events, since, at, earliest, stamped))
        finally:
            self.line.set_sender(_discard)
            if port.break_condition:
                port.break_condition = False
                self.line.break_off()


def serve_serial(line: RealTimeLine, port: serial.SerialBase, stopped: threading.Event) -> None:
    """Feed what a real serial port receives into ``line`` until ``stopped`` is set.

    Bytes are stamped on arrival and laid back to back ending then (chunks read at once
    cannot show their gaps); a NUL is a break of at least 12 ms that ended as it was read.
    A NUL read together with characters cannot show the marking between them either: the
    chunk's events share the marking its frames leave free since the previous chunk
    (:func:`serial_arrivals`), and the break carries that room as its doubt.
    """
    floor = line.now()
    while not stopped.is_set():
        data = port.read(max(1, port.in_waiting))
        if not data:
            continue
        at = line.now()
        frames = chunk_frames(len(data), at, floor)
        for run, (first, end), doubt in serial_arrivals(data, frames, floor):
            if run == b"\x00":
                line.break_on(end - max(BREAK_MIN, CHAR_TIME), doubt)
                line.break_off(end, doubt)
            else:
                line.tool_bytes(run, first)
        floor = frames[-1][1]


def serial_arrivals(
    data: bytes, frames: list[tuple[float, float]], floor: float
) -> list[tuple[bytes, tuple[float, float], float]]:
    """A UART chunk as runs (a NUL alone, characters back to back), each with the (start,
    end) of its frames and its doubt (s). Alone, a run keeps the frames
    :func:`~conformance.links.stamps.chunk_frames` gave it; several share out the marking
    the chunk's frames leave free after ``floor`` (the previous frame's end), evenly and in
    order, the last still ending at the chunk's arrival (:func:`~.arrivals.step` apart), and
    each may be off by all of it."""
    runs: list[bytes] = []
    for byte in data:
        if runs and byte != 0 and runs[-1][:1] not in (b"", b"\x00"):
            runs[-1] += bytes([byte])
        else:
            runs.append(bytes([byte]))
    free = max(0.0, frames[0][0] - floor) if len(runs) > 1 else 0.0
    gap = step(free, len(runs))
    out = []
    k = 0
    for index, run in enumerate(runs):
        shift = (len(runs) - 1 - index) * gap
        out.append((run, (frames[k][0] - shift, frames[k + len(run) - 1][1] - shift), free))
        k += len(run)
    return out


class ArrivalReader:
    """Reads a recorder's socket as groups of bytes that arrived together: ``(data, since,
    at, stamped)``, ``at`` the latest the bytes can have arrived, ``since`` the earliest,
    ``stamped`` whether ``at`` is the kernel's receive stamp (else: when the read returned).

    On Linux every byte comes with the kernel's receive stamp of its packet
    (``SO_TIMESTAMPNS``), taken as it arrived, however late this thread then ran (CI, stop
    45: a late read made a 13 ms break look 6 ms long, and the tap heard '@'); bytes of one
    stamp (one packet, or packets the kernel merged while nobody read) are one group. Without
    stamps a group is one ``recv`` stamped as it returned, and so is a packet the kernel gave
    no stamp: it switches timestamping on for the system lazily (a deferred work item), and
    packets that arrive before that carry none (measured: 142 of 150 first packets on fresh
    sockets of an otherwise quiet machine). Either way a group came after the
    one before it: ``since`` is that group's ``at`` (the first: ``opened``, when the server
    began to listen; not when this reader started, which may be late too).

    Before it waits, a read notes when it last saw the socket empty (``empty_at``, looked
    at every :data:`EMPTY_POLL` while idle): the bytes it then reads all came after that.
    A stamp cannot show packets the kernel merged while nobody read (the merged ones take
    the later stamp), but they can only have come since the socket was last seen empty:
    a prompt reader bounds that span to about a poll, a late one shows it long.

    The kernel can say more where it counts the segments it received (TCP_INFO,
    :func:`~conformance.links.kernel_stamps.data_segments_in`): counted as the reader saw
    the socket empty, and again after a read, a read of as many stamp groups as segments
    came since merged none of them into a wholly unread one, so its first group's stamp is
    when the first of them arrived, and the socket was empty until then (``empty_at``
    that stamp, however late the reader woke). Then a line idle for :data:`ACTIVE_WINDOW`
    blocks in ``select`` up to :data:`RECV_POLL` instead of looking every
    :data:`EMPTY_POLL`; inside the window it still looks, so a read that merged segments
    keeps the look's bound.
    """

    def __init__(self, sock: socket.socket, clock: Callable[[], float], opened: float) -> None:
        self.sock = sock
        self.clock = clock
        self.since = opened
        self.empty_at = opened
        self.stamped = self.ask_for_stamps(sock)
        #: segments counted when the socket was last seen empty (None: not since the last
        #: read, or the kernel does not count them)
        self.counted: int | None = None
        self.counts = self.stamped and data_segments_in(sock) is not None

    @staticmethod
    def ask_for_stamps(sock: socket.socket) -> bool:
        """Have the kernel stamp what ``sock`` (or, a listener, what its connections)
        receive; whether it will."""
        if not (sys.platform.startswith("linux") and STAMP_SPACE):
            return False
        try:
            sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        except OSError:
            return False
        return True

    def read(self) -> list[tuple[bytes, float, float, bool]] | None:
        """The next groups (waits up to :meth:`wait`, else TimeoutError); None: closed."""
        counted = data_segments_in(self.sock) if self.counts else None
        looked = self.clock()  # before the look: whatever it finds came after this
        if not self._readable(0.0):
            self.empty_at = max(self.empty_at, looked)
            self.counted = counted  # every segment counted was queued, and is read
            if not self._readable(self.wait(looked)):
                raise TimeoutError
        if not self.stamped:
            data = self.sock.recv(4096)
            if not data:
                return None
            return [self._group(data, self.clock(), False)]
        got = [self._stamped_byte()]
        if not got[0][0]:
            return None
        got += [self._stamped_byte() for _ in range(self._waiting())]
        now, now_ns = bracketed_wall(self.clock, TIGHT_BRACKET_NS / 1e9)
        groups: list[tuple[bytes, float, float, bool]] = []
        for stamp, run in itertools.groupby(got, key=lambda b: b[1]):
            data = b"".join(b for b, _ in run)
            age = max(0.0, (now_ns - stamp) / 1e9) if stamp is not None else 0.0
            groups.append(self._group(data, now - age, stamp is not None))
        self._empty_until_first(groups)
        return groups

    def wait(self, looked: float) -> float:
        """How long a read waits on an empty socket seen at ``looked``: :data:`EMPTY_POLL`,
        or :data:`RECV_POLL` where segments are counted and the line has been idle for
        :data:`ACTIVE_WINDOW`."""
        idle = self.counts and looked - self.since >= ACTIVE_WINDOW
        return RECV_POLL if idle else EMPTY_POLL

    def _empty_until_first(self, groups: list[tuple[bytes, float, float, bool]]) -> None:
        """``empty_at`` at the first group's stamp when the kernel counted as many segments
        since the socket was seen empty as there are groups: each group then began with a
        segment of its own (a segment merged into a wholly unread one leaves fewer groups;
        one merged into a partly read one splits it, and the later group's span starts at
        the earlier's stamp, its ``since``), and the first came to an empty socket."""
        counted, self.counted = self.counted, None
        if counted is None or not groups or not groups[0][3]:
            return
        now_counted = data_segments_in(self.sock)
        if now_counted is not None and now_counted - counted == len(groups):
            self.empty_at = max(self.empty_at, groups[0][2])

    def _readable(self, wait: float) -> bool:
        """Whether the socket has bytes (or its end) to read within ``wait`` s."""
        ready, _, _ = select.select([self.sock], [], [], wait)
        return bool(ready)

    def _group(self, data: bytes, at: float, stamped: bool) -> tuple[bytes, float, float, bool]:
        at = max(at, self.since)  # a clock step back must not reorder the recorder's events
        since, self.since = self.since, at
        return data, since, at, stamped

    def _waiting(self) -> int:
        """How many received bytes the socket holds (Linux, where stamps are asked for: a
        read of one more would wait for it)."""
        import fcntl  # POSIX only: the module must import where there are no stamps
        import termios

        waiting = bytearray(4)
        fcntl.ioctl(self.sock.fileno(), termios.FIONREAD, waiting)
        return int.from_bytes(waiting, sys.byteorder)

    def _stamped_byte(self) -> tuple[bytes, int | None]:
        """One byte and its packet's kernel stamp (wall-clock ns; None if none came)."""
        return recv_stamped_byte(self.sock)
