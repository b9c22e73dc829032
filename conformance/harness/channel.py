"""Lines to and from a harness: a child process (``exec:``) or a Unix socket (``unix:``).

Everything the harness does is untrusted and bounded: each reply must come within
``reply_timeout`` seconds of wall time, be one line of at most ``MAX_LINE`` characters, and be
the only line answering the message (a second line is a flood). A child that crashes, hangs or
exits is reported with its exit status and the tail of its stderr, and is always reaped.
"""

from __future__ import annotations

import contextlib
import os
import select
import shlex
import signal
import socket
import subprocess
import threading
import time
from collections import deque
from collections.abc import Callable

from ..links.base import LinkError
from .protocol import (
    MAX_LINE,
    MAX_LOG_LINES,
    HarnessProtocolError,
    LogLine,
    Plan,
    Role,
    check_line,
    hello,
    is_log,
    parse_heard,
    parse_hello_features,
    parse_log,
    parse_plan,
    us,
)

#: Wall time a harness has to answer one message (its own work is microseconds).
REPLY_TIMEOUT = 5.0
#: Wall time a harness has to answer ``hello`` (it may load firmware images or models first).
HELLO_TIMEOUT = 30.0
#: Wall time a child has to exit after ``bye`` before it is terminated, then killed.
EXIT_GRACE = 1.0
#: Stderr kept for the report.
STDERR_TAIL = 2000


class HarnessError(LinkError):
    """The harness failed (protocol error, crash, hang, exit): the run stops with an ERROR
    naming the harness, never a verdict about the device under test."""


class Channel:
    """One harness connection: ``ask(line)`` sends a message and returns its one reply."""

    def __init__(self, describe: str, reply_timeout: float = REPLY_TIMEOUT) -> None:
        self.describe = describe
        self.reply_timeout = reply_timeout
        self._buffer = b""
        self._read_fd = -1
        self._write_fd = -1
        self.closed = False
        self.last_sent = ""
        self.failure: str | None = None  # why the harness failed, once it has
        self.logs: list[LogLine] = []  # a recorder harness's log lines, in order
        self.version = 1  # the protocol version the harness answered hello with
        self.features: frozenset[str] = frozenset()  # what it added to it (``2+batch``)
        self.last_plan: Plan | None = None  # the plan it answered last (a repeat is told apart)

    # subclass hooks
    def status(self) -> str:
        """What became of the harness (exit code, stderr tail), for error messages."""
        return ""

    def _release(self) -> None: ...

    def fail(self, reason: str) -> HarnessError:
        self.close()
        status = self.status()
        after = f" (after the tool sent {self.last_sent!r})" if self.last_sent else ""
        self.failure = f"harness {self.describe}: {reason}{after}" + (
            f"; {status}" if status else ""
        )
        return HarnessError(self.failure)

    def send(self, line: str) -> None:
        if self.closed:
            raise HarnessError(f"harness {self.describe} is closed")
        if not self._buffer and select.select([self._read_fd], [], [], 0)[0]:
            chunk = self._read_chunk()  # written since its last answer, unasked
            if not chunk:
                raise self.fail("the harness closed its output (exited?)")
            self._buffer += chunk
        if self._buffer:
            raise self.fail(f"unsolicited output {self._buffer[:80]!r}")
        last, self.last_sent = self.last_sent, line
        self._write((line + "\n").encode("ascii"), last)

    def _write(self, data: bytes, last: str) -> None:
        """Write ``data`` only while the harness reads its input, ``select.PIPE_BUF`` bytes
        at a time (never more than the pipe has room for, so no write blocks): a harness
        that stopped reading (it floods, or hangs) while its output fills its own pipe
        would otherwise hold the tool in ``os.write`` and the harness in its write for
        ever, the one hang the channel's bounds did not cover. What the harness writes
        meanwhile answers no message but ``last``, already answered: a reply too many. No
        room within ``reply_timeout`` s: hung."""
        view = memoryview(data)
        deadline = time.monotonic() + self.reply_timeout
        while view:
            left = deadline - time.monotonic()
            readable, writable, _ = select.select(
                [self._read_fd], [self._write_fd], [], max(left, 0)
            )
            if readable:
                chunk = self._read_chunk()
                if not chunk:
                    raise self.fail("the harness closed its output (exited?)")
                raise self.fail(f"more than one reply to {last!r}: also {chunk[:80]!r}")
            if not writable:
                raise self.fail(
                    f"the harness has not read its input for {self.reply_timeout:g} s (hung?)"
                )
            try:
                view = view[os.write(self._write_fd, view[: select.PIPE_BUF]) :]
            except OSError as exc:
                raise self.fail(f"cannot write to the harness ({exc.strerror or exc})") from exc

    def _read_chunk(self) -> bytes:
        try:
            return os.read(self._read_fd, 4096)
        except OSError as exc:
            raise self.fail(f"cannot read from the harness ({exc.strerror or exc})") from exc

    def receive(self, timeout: float | None = None) -> str:
        deadline = time.monotonic() + (self.reply_timeout if timeout is None else timeout)
        while b"\n" not in self._buffer:
            if len(self._buffer) > MAX_LINE:
                raise self.fail(f"reply longer than {MAX_LINE} characters: {self._buffer[:80]!r}")
            left = deadline - time.monotonic()
            ready = select.select([self._read_fd], [], [], max(left, 0))[0] if left > 0 else []
            if not ready:
                waited = self.reply_timeout if timeout is None else timeout
                raise self.fail(f"no reply within {waited:g} s (hung?)")
            chunk = self._read_chunk()
            if not chunk:
                raise self.fail("the harness closed its output (exited?)")
            self._buffer += chunk
        raw, _, self._buffer = self._buffer.partition(b"\n")
        try:
            return check_line(raw)
        except HarnessProtocolError as exc:
            raise self.protocol_error(exc) from exc

    def ask(self, line: str, timeout: float | None = None) -> str:
        self.send(line)
        return self.answer(timeout)

    def answer(
        self, timeout: float | None = None, aside: Callable[[str], bool] | None = None
    ) -> str:
        """The one line answering the message sent last (:meth:`send` then :meth:`answer`
        lets the caller work while the harness thinks). Lines ``aside`` takes (returns True
        for) come before that answer and are not it: a recorder harness's ``log`` lines."""
        reply = self.receive(timeout)
        try:
            while aside is not None and aside(reply):
                reply = self.receive(timeout)
        except HarnessProtocolError as exc:
            raise self.protocol_error(exc) from exc
        if self._buffer:  # more than the one line that answers the message
            raise self.fail(
                f"more than one reply to {self.last_sent!r}: also {self._buffer[:80]!r}"
            )
        return reply

    def greet(self, role: Role) -> str:
        """Exchange hellos (with the longer start-up allowance); the harness's name."""
        reply = self.ask(hello(role), max(HELLO_TIMEOUT, self.reply_timeout))
        try:
            name, self.version, self.features = parse_hello_features(reply)
            return name
        except HarnessProtocolError as exc:
            raise self.protocol_error(exc) from exc

    def plan(self, message: str, role: Role, now: float, since: float | None = None) -> Plan:
        """Send a line event (``now`` is its time in s; ``since`` the START of the frame a
        ``char``/``break`` reports) and return the checked plan."""
        self.send(message)
        return self.read_plan(role, now, since)

    def read_plan(self, role: Role, now: float, since: float | None = None) -> Plan:
        """The checked plan answering the line event sent last (at ``now`` s); a recorder
        harness's ``log`` lines before it go to :attr:`logs`."""
        reply = self.answer(aside=self._take_log if role is Role.RECORDER else None)
        try:
            plan = parse_plan(
                reply,
                role,
                us(now),
                None if since is None else us(since),
                self.version,
                self.last_plan,
            )
            self.last_plan = plan
            return plan
        except HarnessProtocolError as exc:
            raise self.protocol_error(exc) from exc

    def read_heard(self, role: Role, frames: list[tuple[int, int, int]]) -> tuple[int, Plan]:
        """The answer to a ``chars`` message of ``frames`` ``(wire, start us, end us)``: how
        many the harness heard and its checked plan after the last of them (the plan it had
        before them counts as the previous one only if it heard one: in between it planned
        nothing it had to tell)."""
        reply = self.answer()
        try:
            taken, text = parse_heard(reply, len(frames))
            _, start, end = frames[taken - 1]
            previous = self.last_plan if taken == 1 else None
            plan = parse_plan(text, role, end, start, self.version, previous)
        except HarnessProtocolError as exc:
            raise self.protocol_error(exc) from exc
        self.last_plan = plan
        return taken, plan

    def _take_log(self, text: str) -> bool:
        if not is_log(text):
            return False
        if len(self.logs) >= MAX_LOG_LINES:
            raise HarnessProtocolError(f"more than {MAX_LOG_LINES} log lines in one job", text)
        self.logs.append(parse_log(text))
        return True

    def protocol_error(self, exc: HarnessProtocolError) -> HarnessError:
        return self.fail(f"protocol error: {exc.reason}: {exc.line[:MAX_LINE]!r}")

    def finish(self, farewell: str) -> None:
        """End a conversation that went well: say ``farewell``, then read until the harness
        closes its output (at most ``reply_timeout`` s, as for any answer). A line arriving
        now answers no message: the harness wrote something unasked earlier and every answer
        since was read against the wrong message, which no check on a single line can see.
        Raise, so the run's records are not trusted. Not ``EXIT_GRACE`` (1 s): a busy machine
        held a harness's late line longer than that after ``bye`` (a CI-like load: nice 19
        beside two CPU burners) and the records were trusted; a harness that exits at
        ``bye``, as every one should, ends the wait at once."""
        if self.closed:
            return
        self.send(farewell)
        leftover = b""
        deadline = time.monotonic() + max(EXIT_GRACE, self.reply_timeout)
        while len(leftover) <= MAX_LINE and (left := deadline - time.monotonic()) > 0:
            if not select.select([self._read_fd], [], [], left)[0]:
                break
            chunk = self._read_chunk()
            if not chunk:
                break
            leftover += chunk
        if leftover:
            raise self.fail(
                f"output out of step: {leftover[:80]!r} came after the last answer, so the "
                "answers were read against the wrong messages (a line written unasked?)"
            )
        self.close()

    def close(self, farewell: str | None = None) -> None:
        """Say ``farewell`` if still possible, then release the harness (idempotent)."""
        if self.closed:
            return
        if farewell is not None and select.select([], [self._write_fd], [], 0)[1]:
            with contextlib.suppress(OSError):  # room for it now, or none: never a wait
                os.write(self._write_fd, (farewell + "\n").encode("ascii"))
        self.closed = True
        self._release()


class ChildChannel(Channel):
    """A harness program started by the tool; its stdin/stdout carry the protocol."""

    def __init__(
        self,
        command: str,
        env: dict[str, str] | None = None,
        reply_timeout: float = REPLY_TIMEOUT,
    ) -> None:
        super().__init__(repr(command), reply_timeout)
        try:
            argv = shlex.split(command)
        except ValueError as exc:
            raise HarnessError(f"harness command {command!r}: {exc}") from exc
        if not argv:
            raise HarnessError("exec: needs a program, e.g. exec:./my-sensor-harness")
        self._stderr: deque[str] = deque()
        self._stderr_size = 0
        try:
            self.proc = subprocess.Popen(
                argv,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                env=None if env is None else {**os.environ, **env},
                start_new_session=True,  # its own process group: killed whole, never orphaned
            )
        except OSError as exc:
            raise HarnessError(f"cannot start harness {command!r}: {exc}") from exc
        assert self.proc.stdin and self.proc.stdout and self.proc.stderr
        self._read_fd = self.proc.stdout.fileno()
        self._write_fd = self.proc.stdin.fileno()
        self._drain = threading.Thread(target=self._collect_stderr, daemon=True)
        self._drain.start()

    def _collect_stderr(self) -> None:
        """Keep the tail of stderr; reading all of it keeps a chatty child from blocking."""
        assert self.proc.stderr
        for raw in iter(lambda: self.proc.stderr.readline(4096), b""):  # type: ignore[union-attr]
            line = raw.decode("utf-8", errors="replace").rstrip("\n")
            self._stderr.append(line)
            self._stderr_size += len(line) + 1
            while self._stderr_size > STDERR_TAIL and len(self._stderr) > 1:
                self._stderr_size -= len(self._stderr.popleft()) + 1

    def stderr_tail(self) -> str:
        self._drain.join(timeout=0.5)
        return "\n".join(self._stderr)[-STDERR_TAIL:]

    def status(self) -> str:
        code = self.proc.returncode
        if code is None:
            state = "still running, stopped by the tool"
        elif code < 0:
            state = f"killed by signal {signal.Signals(-code).name}"
        else:
            state = f"exit status {code}"
        tail = self.stderr_tail().strip()
        return state + (f"; stderr tail:\n{tail}" if tail else "; no stderr")

    def _release(self) -> None:
        """Close stdin, give the child ``EXIT_GRACE`` to exit, then SIGTERM/SIGKILL its group;
        always wait for it, so no zombie is left."""
        for pipe in (self.proc.stdin, self.proc.stdout):  # a flooding child gets EPIPE
            with contextlib.suppress(OSError):
                pipe.close()  # type: ignore[union-attr]
        try:
            self.proc.wait(timeout=EXIT_GRACE)
        except subprocess.TimeoutExpired:
            for sig in (signal.SIGTERM, signal.SIGKILL):
                with contextlib.suppress(OSError):
                    os.killpg(self.proc.pid, sig)
                try:
                    self.proc.wait(timeout=EXIT_GRACE)
                    break
                except subprocess.TimeoutExpired:
                    continue
        self._drain.join(timeout=1.0)
        with contextlib.suppress(OSError):
            self.proc.stderr.close()  # type: ignore[union-attr]


class SocketChannel(Channel):
    """A harness already listening on a Unix stream socket (``unix:PATH``)."""

    def __init__(self, path: str, reply_timeout: float = REPLY_TIMEOUT) -> None:
        super().__init__(f"unix:{path}", reply_timeout)
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            self.sock.settimeout(reply_timeout)
            self.sock.connect(path)
        except OSError as exc:
            self.sock.close()
            raise HarnessError(f"cannot connect to harness socket {path}: {exc}") from exc
        self.sock.settimeout(None)
        self._read_fd = self._write_fd = self.sock.fileno()

    def _release(self) -> None:
        with contextlib.suppress(OSError):
            self.sock.shutdown(socket.SHUT_RDWR)
        self.sock.close()
