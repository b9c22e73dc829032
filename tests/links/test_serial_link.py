"""The real-link layer: arrival stamps, parity kept on the wire, bounded reads, breaks as
achieved, links without breaks, ports that fail to open or vanish. Only loopback I/O (pty,
loop://, 127.0.0.1); every test is bounded."""

from __future__ import annotations

import errno
import os
import socket
import threading
import time

import pytest

from conformance.emulator_server.realtime import RealTimeLine
from conformance.emulator_server.servers import TcpEmulatorServer
from conformance.links.echo import EchoMode
from conformance.links.errors import (
    BreakUnsupported,
    PortMissing,
    PortUnavailable,
    PortVanished,
    explain_open_failure,
)
from conformance.links.factory import open_real_link, port_kind
from conformance.links.stamps import MAX_LEAD, chunk_frames
from conformance.ports import PortError, open_port
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.engine import ToolRecorder
from conformance.transcript import EventKind, to_wire_7e1

pty_only = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pseudo-terminal")


# -- arrival stamps ---------------------------------------------------------------------------
def test_a_lone_byte_ended_when_it_arrived():
    assert chunk_frames(1, 1.0, 0.0) == [(1.0 - CHAR_TIME, 1.0)]


def test_a_chunk_is_taken_as_back_to_back_frames_ending_at_arrival():
    frames = chunk_frames(3, 1.0, 0.0)
    assert frames[-1][1] == pytest.approx(1.0)
    for (_, end), (start, _) in zip(frames, frames[1:], strict=False):
        assert start == pytest.approx(end)


def test_no_frame_starts_before_the_previous_one_ended():
    # the previous byte was stamped late; this one came on time: no overlap, no false gap
    frames = chunk_frames(1, 1.0, floor=1.0 - CHAR_TIME + 0.003)
    assert frames[0][0] == pytest.approx(1.0 - CHAR_TIME + 0.003)


def test_a_flood_overlaps_rather_than_running_into_the_future():
    frames = chunk_frames(1000, 1.0, floor=0.99)
    assert frames[-1][1] <= 1.0 + MAX_LEAD + 1e-9
    assert frames[0][0] < 0.99  # more bytes than 1200 baud could carry: visibly overlapping


def _echo_then_reply(gap_after_echo: float):
    """A link that heard the echo of ``0D1!`` a character at a time, then the reply's first
    character alone, stamped ``gap_after_echo`` s after the echo's end (negative: before it
    could have started): the meter's figure for the command-to-reply gap."""
    from conformance.links.echo import Expected

    link = open_real_link("loop://", echo=EchoMode.ON)  # nothing is written: the line is idle
    try:
        link.echo.expect([Expected(to_wire_7e1(ord(c)), CHAR_TIME) for c in "0D1!"])
        wire = [to_wire_7e1(ord(c)) for c in "0D1!"]
        for k, byte in enumerate(wire):
            link._arrived(bytes([byte]), 1.0 + k * CHAR_TIME)
        echo_end = 1.0 + 3 * CHAR_TIME
        link._arrived(bytes([to_wire_7e1(ord("0"))]), echo_end + gap_after_echo + CHAR_TIME)
        reply = [e for e in link.transcript.events if e.kind is EventKind.CHAR][-1]
        assert reply.start >= echo_end - 1e-9  # placed after the echo, never into it
        return link.meter.between(echo_end, reply.start), link.meter.uncertainty()
    finally:
        link.close()


def test_a_reply_stamped_before_the_echo_ended_taints_the_gap_by_a_character():
    """The usb16-echo false FAIL: a reply start stamped 0.4 ms before the command's echo
    ended was placed at its end and measured as a 0.00 ms gap at the regular figure, a FAIL
    of R-7.0-09 for a sensor that waited 9.4 ms. An intact echo proves the command ended
    before the reply began, so the overlap shows the stamps wrong by more than it: the gap
    is worth no more than a whole character there."""
    between, regular = _echo_then_reply(-0.4e-3)
    assert between >= CHAR_TIME > regular


def test_a_reply_stamped_after_the_echo_keeps_the_regular_figure():
    between, regular = _echo_then_reply(9.4e-3)
    assert between == regular


# -- port kinds and open errors ---------------------------------------------------------------
@pytest.mark.parametrize(
    ("port", "kind"),
    [
        ("/dev/ttyUSB0", "serial"),
        ("COM3", "serial"),
        ("rfc2217://127.0.0.1:4001", "rfc2217"),
        ("socket://10.0.0.2:7000", "socket"),
        ("loop://", "loop"),
    ],
)
def test_port_kinds(port, kind):
    assert port_kind(port) == kind


def test_missing_device_is_a_port_error_with_what_to_do():
    with pytest.raises(PortError) as caught:
        open_port("/dev/ttyUSB-sdi12-missing")
    assert isinstance(caught.value, PortMissing)  # the main command adds "--port sim"
    assert "does not exist" in str(caught.value) and "ls /dev/ttyUSB*" in str(caught.value)


def test_permission_and_busy_messages_say_what_to_do():
    denied = explain_open_failure(
        "/dev/ttyUSB0", "serial", OSError(errno.EACCES, "Permission denied")
    )
    assert "dialout" in denied
    busy = explain_open_failure(
        "/dev/ttyUSB0", "serial", OSError(errno.EBUSY, "Device or resource busy")
    )
    assert "busy" in busy


def test_nobody_listening_is_a_port_error():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        free = probe.getsockname()[1]
    with pytest.raises(PortUnavailable, match="Is the server running"):
        open_real_link(f"rfc2217://127.0.0.1:{free}")


# -- reading and writing ----------------------------------------------------------------------
def test_loop_link_keeps_the_raw_bits_and_declares_no_break():
    link = open_real_link("loop://", echo=EchoMode.OFF)  # loop:// plays a DUT sending them
    try:
        assert link.info.kind == "loop" and not link.info.can_break
        good, bad = to_wire_7e1(ord("0")), to_wire_7e1(ord("0")) ^ 0x80
        link.write(bytes([good, bad]))
        got = link.receive(link.now() + 0.2, until=lambda chars: len(chars) == 2)
        assert [e.wire for e in got] == [good, bad]
        assert [e.parity_ok for e in got] == [True, False]
        assert all(e.end - e.start == pytest.approx(CHAR_TIME) for e in got)
    finally:
        link.close()


@pytest.mark.realtime  # wall-clock bounds: in CI's niced session one took 156 ms for 109
def test_receive_on_a_silent_line_is_bounded_by_its_deadline():
    """The wait ends near its deadline, not at some read timeout of its own (0.5 s and up):
    the bound leaves room for a busy host, never for a wait that ignores the deadline."""
    link = open_real_link("loop://")
    try:
        started = time.monotonic()
        assert link.receive(link.now() + 0.05) == []
        took = time.monotonic() - started
        assert 0.05 <= took < 0.05 + CHAR_TIME + link.info.timing_uncertainty + 0.2
        started = time.monotonic()
        assert link.receive(link.now() - 1.0) == []  # a passed deadline: what is queued, now
        assert time.monotonic() - started < 0.1
    finally:
        link.close()


@pytest.mark.realtime  # host-timed gaps: a starved process stretches them
def test_write_with_a_gap_spaces_the_characters():
    link = open_real_link("loop://", echo=EchoMode.OFF)  # the stamps of the write itself
    try:
        events = link.write(b"0I!", gap=0.010)
        starts = [e.start for e in events]
        gaps = [b - a - CHAR_TIME for a, b in zip(starts, starts[1:], strict=False)]
        assert all(0.0095 <= g < 0.015 for g in gaps), gaps
    finally:
        link.close()


@pty_only
def test_wrong_parity_from_a_serial_device_is_kept_as_evidence():
    controller, device = os.openpty()
    link = open_real_link(os.ttyname(device))
    try:
        assert link.info.kind == "serial" and link.info.can_break
        os.write(controller, bytes([to_wire_7e1(ord("0")) ^ 0x80]))
        got = link.receive(link.now() + 0.5, until=lambda chars: True)
        assert len(got) == 1 and not got[0].parity_ok
    finally:
        link.close()
        os.close(controller)
        os.close(device)


@pytest.mark.realtime  # breaks timed by the host: run serially
@pty_only
def test_uart_break_records_the_duration_it_held():
    controller, device = os.openpty()
    link = open_real_link(os.ttyname(device))
    try:
        event = link.send_break(13e-3)
        assert event.kind is EventKind.BREAK
        # what was held, not what was asked: at least 13 ms, and an overshoot of the host's
        # timer (3.4 ms once on a loaded CI machine, beyond the old fixed 16 ms bound) within
        # the uncertainty the link states for a host-timed break
        assert 13e-3 <= event.duration <= 13e-3 + event.uncertainty, event
        assert f"held {event.duration * 1e3:.2f} ms" in event.text, event.text
        assert "break_condition" in event.text
    finally:
        link.close()
        os.close(controller)
        os.close(device)


# -- links without breaks; a port that vanishes -------------------------------------------------
class _OneShotServer:
    """Accepts one TCP client, records what it sends, and hangs up when told."""

    def __init__(self) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.received = bytearray()
        self.hang_up = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        conn, _ = self.listener.accept()
        conn.settimeout(0.02)
        with conn:
            while not self.hang_up.is_set():
                try:
                    data = conn.recv(100)
                except TimeoutError:
                    continue
                if not data:
                    break
                self.received += data
        self.listener.close()


def test_socket_link_cannot_break_and_the_engine_sends_anyway():
    server = _OneShotServer()
    link = open_real_link(f"socket://127.0.0.1:{server.port}")
    try:
        assert link.info.kind == "socket" and not link.info.can_break
        with pytest.raises(BreakUnsupported):
            link.send_break(13e-3)
        exchange = ToolRecorder(link).transact("0!", retries=False)
        assert exchange.attempts[0].break_event is None
        assert not exchange.answered
        notes = [e.text for e in link.transcript if e.kind is EventKind.NOTE]
        breaks = [n for n in notes if "no break" in n]
        echo = "no echo of the tool's characters: the interface does not echo"
        assert breaks and set(notes) - set(breaks) <= {echo}
        deadline = time.monotonic() + 1
        while len(server.received) < 2 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert bytes(b & 0x7F for b in server.received) == b"0!"
    finally:
        server.hang_up.set()
        link.close()


def test_a_vanishing_port_raises_from_the_next_call_within_a_bound():
    server = _OneShotServer()
    link = open_real_link(f"socket://127.0.0.1:{server.port}")
    try:
        server.hang_up.set()
        server.thread.join(timeout=1)
        started = time.monotonic()
        with pytest.raises(PortVanished, match="failed during the run"):
            link.receive(link.now() + 2.0)
        assert time.monotonic() - started < 1.0
    finally:
        link.close()


# -- RFC 2217 breaks --------------------------------------------------------------------------
class _BreakRecorder:
    """A bus device that only notes the breaks it hears (start, end)."""

    name = "recorder"

    def __init__(self) -> None:
        self.breaks: list[tuple[float, float]] = []
        self.chars: list[int] = []

    def on_break(self, start: float, end: float) -> None:
        self.breaks.append((start, end))

    def on_char(self, wire: int, start: float, end: float) -> None:
        self.chars.append(wire)

    def next_frame(self):
        return None

    def pop_frame(self):
        raise AssertionError("never offers a frame")


def _served_break(duration: float, exact: bool = False) -> tuple[object, tuple[float, float]]:
    """Send one break of ``duration`` over RFC 2217 to a line that records what it heard."""
    device = _BreakRecorder()
    line = RealTimeLine(device, lambda data: None).start()
    server = TcpEmulatorServer(line, "127.0.0.1", 0)
    serving = threading.Thread(target=server.serve, daemon=True)
    serving.start()
    link = open_real_link(server.url)
    try:
        assert link.info.kind == "rfc2217" and link.info.can_break
        event = link.send_break(duration, exact=exact)
        link.wait(0.02)
        deadline = time.monotonic() + 1
        while not device.breaks and time.monotonic() < deadline:
            time.sleep(0.005)
        (heard,) = device.breaks
        return event, heard
    finally:
        link.close()
        server.stop()
        serving.join(timeout=2)
        line.stop()


def _served_break_heard(
    duration: float, exact: bool = False, tries: int = 3
) -> tuple[object, tuple[float, float]]:
    """:func:`_served_break`, tried again (up to ``tries`` in all) while the line did not hear
    the break as long as the link stamped it. The emulated line stamps a break's edges when
    its thread handles the two SET_CONTROL messages; a thread starved for longer than the
    break handles both at once and hears 0 ms (CI beside two other sessions: a 5.05 ms
    break heard as 0.0 ms). That is the test machine, not the link; a link that does not
    hold breaks as it stamps them fails every try, and the last is what the test judges."""
    for _ in range(tries):
        event, heard = _served_break(duration, exact)
        if abs(heard[1] - heard[0] - event.duration) <= event.uncertainty:
            break
    return event, heard


def _held_within_its_uncertainty(event, asked: float) -> None:
    """A host-timed hold may overrun by the link's declared uncertainty; more than that is
    the shared machine failing to wake the sleeping thread in time (the event still says
    what was held, so no verdict is misled): skipped with the figure, as busy."""
    overrun = event.duration - asked
    if overrun >= event.uncertainty:
        pytest.skip(
            f"the machine was too busy to keep real time: the host held the break "
            f"{overrun * 1e3:.2f} ms past {asked * 1e3:.0f} ms (declared "
            f"{event.uncertainty * 1e3:.1f} ms)"
        )


def _heard_as_stamped(event, heard: float) -> None:
    """The line held the break as long as the event says, within the uncertainty the event
    itself declares (both ends are stamped by one busy host: a fixed few ms would be a
    figure of this machine, not of the link)."""
    assert abs(heard - event.duration) <= event.uncertainty, (heard, event)


@pytest.mark.realtime  # breaks timed by the host: run serially
def test_rfc2217_short_break_is_a_nul_timed_by_the_uart():
    """A 13 ms break is a NUL at 692 baud: the line holds spacing for exactly 9 bit times,
    whatever the host's sleep did, and the event says so with a tiny length uncertainty."""
    event, (start, end) = _served_break(13e-3, exact=True)
    assert event.duration == pytest.approx(9 / 692)
    assert "692 baud" in event.text and "SET-BAUDRATE" in event.text
    assert event.length_uncertainty < 0.2e-3 < event.uncertainty
    assert end - start == pytest.approx(9 / 692, abs=1e-9)  # the line's own arithmetic


@pytest.mark.realtime  # breaks timed by the host: run serially
def test_rfc2217_wake_up_break_is_held_by_set_control():
    """An ordinary wake-up break (not near a threshold) is held with raw SET_CONTROL."""
    event, (start, end) = _served_break_heard(13e-3)
    assert event.duration >= 13e-3, event
    _held_within_its_uncertainty(event, 13e-3)
    assert "SET_CONTROL" in event.text
    _heard_as_stamped(event, end - start)


@pytest.mark.realtime  # breaks timed by the host: run serially
def test_server_that_keeps_its_bit_rate_gets_host_timed_breaks(monkeypatch):
    """A server that does not take SET-BAUDRATE would send the NUL at 1200 baud (7.5 ms of
    spacing, not what was asked): the link sees the refusal and holds the break instead."""
    from conformance.emulator_server import servers

    class Stubborn(servers.VirtualPort):
        @property
        def baudrate(self) -> int:
            return 1200

        @baudrate.setter
        def baudrate(self, _value: int) -> None:
            pass

    monkeypatch.setattr(servers, "VirtualPort", Stubborn)
    event, (start, end) = _served_break_heard(5e-3, exact=True)
    assert "SET_CONTROL" in event.text and "baud" not in event.text
    _heard_as_stamped(event, end - start)


@pytest.mark.realtime  # breaks timed by the host: run serially
def test_rfc2217_long_break_is_held_by_set_control():
    """Longer than a NUL at the lowest rate can make: held with raw SET_CONTROL messages."""
    event, (start, end) = _served_break_heard(100e-3, exact=True)
    assert event.duration >= 100e-3, event
    _held_within_its_uncertainty(event, 100e-3)
    assert "SET_CONTROL" in event.text
    _heard_as_stamped(event, end - start)
