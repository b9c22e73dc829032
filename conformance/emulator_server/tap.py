"""A listen-only tap on an emulated line (``emulate --tap socket://HOST:PORT``).

On a real bench a bus monitor is one more UART on the wire: it hears every character, the
recorder's and the sensors', and its own transmitter is never connected. The tap gives an
emulated line the same place for a monitor: a raw TCP server (what pyserial's ``socket://``
speaks) whose clients receive each character on the line at its stop bit, a break as the 0x00
a UART reads at its stop-bit sample. Any number of clients may listen; whatever they send is
read and dropped, so a listener can never reach the line.
"""

from __future__ import annotations

import contextlib
import socket
import threading
from collections.abc import Callable
from urllib.parse import urlsplit

from ..ports import PortError

RECV_POLL = 0.1  # s: accept and reads time out this often so a stop is noticed


def parse_tap(url: str) -> tuple[str, int]:
    """``socket://HOST:PORT`` -> (host, port); port 0 lets the OS pick a free one."""
    parts = urlsplit(url)
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "socket" or port is None:
        raise PortError(
            f"--tap wants socket://HOST:PORT (for example socket://127.0.0.1:0), not {url!r}"
        )
    return parts.hostname or "127.0.0.1", port


class TapServer:
    """Serve what the line carries to every connected listener; never pass anything back."""

    def __init__(
        self, host: str, port: int, *, log: Callable[[str], None] = lambda _msg: None
    ) -> None:
        self.log = log
        self.listener = socket.create_server((host, port))
        self.listener.settimeout(RECV_POLL)
        self.address = self.listener.getsockname()[:2]
        self.stopped = threading.Event()
        self._clients: list[socket.socket] = []
        self._lock = threading.Lock()
        self.ignored_bytes = 0  # what listeners sent: dropped, counted for the log and tests
        self._thread = threading.Thread(target=self._accept_loop, name="sdi12-tap", daemon=True)

    @property
    def url(self) -> str:
        return f"socket://{self.address[0]}:{self.address[1]}"

    def start(self) -> TapServer:
        self._thread.start()
        return self

    def send(self, data: bytes) -> None:
        """Hand ``data`` to every listener (the line's thread calls this: never blocks long;
        a listener that cannot keep up or has gone is dropped)."""
        with self._lock:
            clients = list(self._clients)
        for sock in clients:
            try:
                sock.sendall(data)
            except OSError:
                self._drop(sock)

    def stop(self) -> None:
        self.stopped.set()
        if self._thread.is_alive():
            self._thread.join(timeout=1.0)
        with self._lock:
            clients, self._clients = self._clients, []
        for sock in clients:
            with contextlib.suppress(OSError):
                sock.close()

    def _drop(self, sock: socket.socket) -> None:
        with self._lock:
            if sock in self._clients:
                self._clients.remove(sock)
        with contextlib.suppress(OSError):
            sock.close()

    def _accept_loop(self) -> None:
        """Accept listeners; drain and drop what they send (one reader thread each)."""
        try:
            while not self.stopped.is_set():
                try:
                    sock, peer = self.listener.accept()
                except TimeoutError:
                    continue
                except OSError:
                    return
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                sock.settimeout(1.0)  # a listener that stops reading must not stall the line
                with self._lock:
                    self._clients.append(sock)
                self.log(f"tap listener connected from {peer[0]}:{peer[1]} (listen-only)")
                threading.Thread(target=self._drain, args=(sock,), daemon=True).start()
        finally:
            self.listener.close()

    def _drain(self, sock: socket.socket) -> None:
        while not self.stopped.is_set():
            try:
                data = sock.recv(4096)
            except TimeoutError:
                continue
            except OSError:
                break
            if not data:
                break
            self.ignored_bytes += len(data)
        self._drop(sock)
