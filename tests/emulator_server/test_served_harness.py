"""``emulate --harness``: an outside sensor harness served in real time (bench31).

The harness runs on the wall clock the served line keeps: what the recorder sends reaches it
at its stop bit, its ``tx`` go out at their times, a ``wait T`` is answered with ``time T``.
A harness that fails stops the server with its error, never a hang or a server serving a line
that no longer answers.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from pathlib import Path

import pytest
import serial

from conformance.emulator_server.command import emulate_main
from conformance.emulator_server.harness import LineClock, open_served_harness
from conformance.emulator_server.process import EmulatorProcess
from conformance.emulator_server.realtime import RealTimeLine
from conformance.emulator_server.servers import TcpEmulatorServer
from conformance.links.factory import open_real_link
from conformance.links.priority import SERVED_FIRMWARE
from conformance.ports import PortError
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.sim.bus import Frame
from conformance.tool_recorder.engine import ToolRecorder
from tests.harness.test_device import MISBEHAVING, reaped
from tests.support.paths import ROOT

EXAMPLE = f"exec:{sys.executable} {ROOT / 'examples/python/sensor_harness.py'}"


@pytest.fixture
def served_example():
    """The Python example sensor harness behind an in-process RFC 2217 server, a link to it,
    and the line (for its errors)."""
    clock = LineClock()
    device = open_served_harness(EXAMPLE, clock)
    line = RealTimeLine(device, lambda _data: None, clock=clock, on_failure=lambda _exc: None)
    server = TcpEmulatorServer(line, "127.0.0.1", 0)
    line.start()
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    link = open_real_link(server.url)
    yield link, line, device
    link.close()
    server.stop()
    thread.join(timeout=2)
    line.stop()
    device.close()


def test_the_python_example_harness_answers_over_rfc2217(served_example):
    """The harness hears the recorder's characters and its planned reply reaches it."""
    link, line, device = served_example
    exchange = ToolRecorder(link).identify("0")
    assert exchange.ok, exchange.reply_text
    assert "CONFORM" in exchange.reply_text
    assert not line.errors and device.channel.failure is None


@pytest.mark.realtime  # waits the sensor's measurement time in real time
def test_the_served_harness_measures_with_its_service_request(served_example):
    """A reply planned seconds ahead (the service request) goes out at its time."""
    link, line, _device = served_example
    m = ToolRecorder(link).measure(cmds.parse_command("0M!"))
    assert m.values and m.count == len(m.values)
    assert m.service_request_end is not None
    assert not line.errors


class _Alarm:
    """A device that sleeps until ``at`` (a harness that answered ``wait T``), then sends
    ``A`` at once; it logs what it is told, in order."""

    def __init__(self, at: float) -> None:
        self.wake_at: float | None = at
        self.told: list[tuple[str, float]] = []
        self._frame: Frame | None = None

    def wake(self, now: float) -> None:
        self.told.append(("time", now))
        self.wake_at = None
        self._frame = Frame(now, ord("A"), CHAR_TIME)

    def on_break(self, start: float, end: float) -> None:
        self.told.append(("break", end))

    def on_char(self, wire: int, start: float, end: float) -> None:
        self.told.append(("char", end))

    def next_frame(self) -> Frame | None:
        return self._frame

    def pop_frame(self) -> Frame:
        frame, self._frame = self._frame, None
        assert frame is not None
        return frame


def test_the_line_wakes_a_device_at_its_time_after_what_came_before():
    """``wait T``: told ``time T`` (the time it asked for, not a late reading), after a
    recorder character that ended before T, and its character then goes out."""
    sent: list[bytes] = []
    clock = LineClock()
    at = clock() + 0.05
    alarm = _Alarm(at)
    line = RealTimeLine(alarm, sent.append, clock=clock).start()
    try:
        line.tool_bytes(b"0")  # ends 8.3 ms from now, well before the wake-up
        deadline = time.monotonic() + 2
        while not sent and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        line.stop()
    assert [word for word, _ in alarm.told] == ["char", "time"]
    assert alarm.told[1][1] == at
    assert sent == [b"A"]


def test_a_wake_up_due_is_not_told_before_a_recorder_event_due_first():
    clock = LineClock()
    alarm = _Alarm(clock() + 0.002)
    line = RealTimeLine(alarm, lambda _d: None, clock=clock)
    line.tool_bytes(b"0", at=clock() - 0.1)  # its stop bit long past: due before the wake-up
    time.sleep(0.005)
    line._step()  # noqa: SLF001 - the scheduling decision itself, without the thread
    line._step()  # noqa: SLF001
    assert [word for word, _ in alarm.told] == ["char", "time"]


class _Ticker(_Alarm):
    """A device woken every millisecond (a firmware's tick, as the uOS++ sensor's): it logs
    each message's time, the start of the frame a ``char``/``break`` reports."""

    def wake(self, now: float) -> None:
        self.told.append(("time", now))
        self.wake_at = now + 1e-3

    def on_break(self, start: float, end: float) -> None:
        self.told.append(("break", start))

    def on_char(self, wire: int, start: float, end: float) -> None:
        self.told.append(("char", start))


def test_a_ticking_device_never_hears_of_the_past():
    """bench31: the uOS++ sensor, served, never answered after its first reply: a held break
    was told at its end after ``time T`` messages for T inside it (the wakes ran on while the
    break's message waited in the queue), so the firmware heard of a break that began before
    the time it had been told. Now no wake is told at or past the start of a recorder frame
    not yet told, and a frame stamped before the last time told is laid from it."""
    clock = LineClock()
    ticker = _Ticker(clock() + 1e-3)
    line = RealTimeLine(ticker, lambda _d: None, clock=clock).start()
    try:
        time.sleep(0.01)
        line.break_on()
        time.sleep(0.02)
        line.break_off()
        time.sleep(0.005)
        line.tool_bytes(b"0", at=clock() - 0.004)  # stamped 4 ms ago: ticks told since
        time.sleep(0.03)
    finally:
        line.stop()
    times = [at for _, at in ticker.told]
    assert [w for w, _ in ticker.told].count("break") == 1
    assert "char" in [w for w, _ in ticker.told]
    assert times == sorted(times), ticker.told


def test_the_served_firmware_runs_in_a_real_time_class_where_the_line_may():
    """bench31: beside two CPU burners an ordinary harness process answered the uOS++
    sensor's tick wake-ups late, and its reply began 31.44 ms after the command (R-7.0-10
    FAILed on the serving machine's account). The firmware is on the line's critical path:
    it gets a real-time class just below the line's, where the OS grants one."""
    device = open_served_harness(EXAMPLE, LineClock())
    try:
        pid = device.channel.proc.pid  # type: ignore[attr-defined]
        policy = os.sched_getscheduler(pid) & ~getattr(os, "SCHED_RESET_ON_FORK", 0)
        if not device.realtime_priority:
            pytest.skip("the OS grants no real-time class here")
        assert policy == os.SCHED_RR
        assert os.sched_getparam(pid).sched_priority == SERVED_FIRMWARE
    finally:
        device.close()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--harness", "python sensor.py"], "exec:PROGRAM"),
        (["--harness", EXAMPLE, "--faults", "wrong-crc"], "--faults shape the reference"),
        (["--harness", EXAMPLE, "--address", "3"], "--address shape the reference"),
        (["--harness", "exec:/nonexistent/sdi12-harness"], "cannot start harness"),
    ],
)
def test_harness_usage_errors_exit_4(argv, message):
    said: list[str] = []
    assert emulate_main(["--listen", "127.0.0.1:0", *argv], said.append) == 4
    assert message in " ".join(said)


def test_a_harness_that_fails_hello_is_a_usage_error(tmp_path: Path):
    script = tmp_path / "mute.py"
    script.write_text("import sys\nsys.stdin.readline()\nprint('nonsense', flush=True)\n")
    with pytest.raises(PortError, match="harness"):
        open_served_harness(f"exec:{sys.executable} {script}", LineClock())


@pytest.mark.parametrize(
    ("mode", "words"),
    [
        ("garbage", "protocol error"),
        ("exit", "exited"),
        ("brk", "planned a break"),
    ],
)
def test_a_harness_that_fails_while_served_stops_the_server(tmp_path: Path, mode, words):
    """At the first line event (the recorder's break) the harness breaks the protocol, exits,
    or plans a sensor break the real-time line cannot send: the server says why and exits 3
    within seconds, and the harness is reaped."""
    script = tmp_path / "misbehaving.py"
    script.write_text(MISBEHAVING.replace('if MODE == "badbyte":', _BRK + 'if MODE == "badbyte":'))
    pidfile = tmp_path / "harness.pid"
    emulator = EmulatorProcess("--harness", f"exec:{sys.executable} {script} {mode} 1 {pidfile}")
    try:
        port = serial.serial_for_url(emulator.url, baudrate=1200, timeout=0.2)
        port.send_break(0.015)
        port.write(b"0!")
        code = emulator.proc.wait(timeout=10)
        port.close()
    finally:
        emulator.stop()
    text = "\n".join(emulator.log)
    assert code == 3, text
    assert "error: the served device failed, the server stopped: harness" in text
    assert words in text
    assert reaped(pidfile)


#: A mode of the misbehaving harness: a sensor break planned for now (an extension the sim bus
#: plays, which the real-time line refuses).
_BRK = """if MODE == "brk":
            now = int(fields[1])
            print(f"brk {now} {now + 20000}", flush=True)
            continue
        """
