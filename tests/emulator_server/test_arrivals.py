"""Where the served line lays events that reached it together (sans-I/O:
:mod:`conformance.emulator_server.arrivals`, the UART chunks of serve_serial), and how its
socket reads group them (:class:`~conformance.emulator_server.servers.ArrivalReader`)."""

from __future__ import annotations

import socket
import time

import pytest

from conformance.emulator_server.arrivals import (
    SPREAD_MAX,
    Arrival,
    ToolEvent,
    lay,
    merged,
    placed,
)
from conformance.emulator_server.servers import ArrivalReader, serial_arrivals
from conformance.links.stamps import chunk_frames
from conformance.protocol.timing import CHAR_TIME


class _Line:
    """Records what :func:`lay` asks of a line."""

    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def tool_bytes(
        self, data: bytes, at: float | None = None, baud: int = 1200, doubt: float = 0.0
    ) -> None:
        self.calls.append(("bytes", data, at, baud) + ((doubt,) if doubt else ()))

    def break_on(self, at: float | None = None, doubt: float = 0.0) -> None:
        self.calls.append(("on", at, doubt))

    def break_off(self, at: float | None = None, doubt: float = 0.0) -> None:
        self.calls.append(("off", at, doubt))

    def set_rts(self, raised: bool) -> None:
        self.calls.append(("rts", raised))


def test_one_event_is_placed_at_its_arrival_with_no_doubt_of_its_own():
    assert placed(1.0, 1.02, 1) == ([1.02], 0.0)


def test_r_7_0_06_events_read_together_share_the_room_and_carry_all_of_it():
    times, doubt = placed(1.0, 1.02, 2)
    assert times == pytest.approx([1.01, 1.02]) and doubt == pytest.approx(0.02)


def test_a_long_room_places_events_no_further_apart_than_a_conforming_recorder_needs():
    """Spread over 3 s, a break and the marking after it would last a second each, and the
    played sensors would be in standby by the command: placed 25 ms apart, doubted 3 s."""
    times, doubt = placed(0.0, 3.0, 3)
    assert times == pytest.approx([3.0 - 2 * SPREAD_MAX, 3.0 - SPREAD_MAX, 3.0])
    assert doubt == pytest.approx(3.0)


def test_bytes_of_one_rate_merge_and_rts_takes_no_slot():
    events = [
        ToolEvent("rts", on=True),
        ToolEvent("bytes", b"0"),
        ToolEvent("bytes", b"I"),
        ToolEvent("bytes", b"\x00", baud=600),
    ]
    assert [(e.kind, e.data, e.baud) for e in merged(events)] == [
        ("rts", b"", 1200),
        ("bytes", b"0I", 1200),
        ("bytes", b"\x00", 600),
    ]


def test_r_7_0_06_a_break_off_and_command_read_together_are_laid_apart_with_the_room():
    line = _Line()
    events = (ToolEvent("break", on=False), ToolEvent("bytes", b"0"), ToolEvent("bytes", b"!"))
    lay(line, Arrival(events, since=2.0, at=2.03))
    assert line.calls == [
        ("off", pytest.approx(2.015), pytest.approx(0.03)),
        ("bytes", b"0!", 2.03, 1200, pytest.approx(0.03)),
    ]


def test_a_read_of_one_event_is_laid_as_before():
    line = _Line()
    lay(line, Arrival((ToolEvent("break", on=True),), since=2.0, at=2.03))
    assert line.calls == [("on", 2.03, 0.0)]


def test_a_uart_chunk_of_characters_alone_keeps_its_frames():
    frames = chunk_frames(3, 1.0, 0.5)
    assert serial_arrivals(b"0I!", frames, 0.5) == [(b"0I!", (frames[0][0], frames[2][1]), 0.0)]


def test_r_7_0_05_a_nul_read_with_the_command_leaves_the_sensor_marking_to_hear():
    """serve_serial laid a NUL (the recorder's break) and the command read with it back to
    back: a 0 ms marking the played sensor then refused the command for (R-7.0-05)."""
    floor, at = 1.0, 1.05
    frames = chunk_frames(3, at, floor)
    (nul, (_, nul_end), doubt), (text, (first, last), _) = serial_arrivals(b"\x000!", frames, floor)
    assert (nul, text) == (b"\x00", b"0!")
    assert last == pytest.approx(at)  # the last frame still ends as the chunk arrived
    free = at - 3 * CHAR_TIME - floor
    assert first - nul_end == pytest.approx(free / 2)
    assert doubt == pytest.approx(free)


def _pair() -> tuple[socket.socket, socket.socket]:
    listener = socket.create_server(("127.0.0.1", 0))
    with listener:
        client = socket.create_connection(listener.getsockname()[:2])
        server, _ = listener.accept()
    server.settimeout(0.5)
    return client, server


@pytest.mark.parametrize("stamped", [True, False])
def test_each_read_group_comes_after_the_one_before(stamped):
    """With kernel stamps (Linux) or without (a group per recv, stamped as it returned):
    a group's room starts where the previous group's arrival was."""
    client, server = _pair()
    try:
        reader = ArrivalReader(server, time.perf_counter, opened=time.perf_counter())
        reader.stamped = reader.stamped and stamped
        start = reader.since
        client.sendall(b"ab")
        ((data, since, at, _stamped),) = reader.read()
        assert (data, since) == (b"ab", start) and at >= since
        client.sendall(b"cd")
        ((data2, since2, at2, _stamped2),) = reader.read()
        assert (data2, since2) == (b"cd", at) and at2 >= at
        client.close()
        assert reader.read() is None
    finally:
        server.close()


def test_a_late_read_keeps_the_kernels_arrival_stamp():
    client, server = _pair()
    try:
        reader = ArrivalReader(server, time.perf_counter, opened=time.perf_counter())
        if not reader.stamped:
            pytest.skip("no kernel receive stamps on this platform")
        client.sendall(b"a")
        sent = time.perf_counter()
        time.sleep(0.030)  # the reader runs late
        ((_data, since, at, stamped),) = reader.read()
        if stamped:
            assert abs(at - sent) < 0.010, (at - sent) * 1e3
        else:  # the kernel had not switched stamping on yet: the late read is the doubt
            arrival = Arrival((ToolEvent("bytes", b"a"),), since, at, reader.empty_at, False)
            assert arrival.unseen >= at - sent, (arrival.unseen, at - sent)
    finally:
        client.close()
        server.close()


def test_r_7_0_13_characters_read_together_carry_the_span_they_may_have_been_sent_in():
    """The kernel merges packets nobody read yet under the later one's stamp: '0', 20 ms,
    'M!' read late is '0M!' stamped at the 'M!'. Laid back to back, its gap looks 0 ms and
    its start 20 ms late; each character may have been anywhere since the socket was last
    seen empty, and says so."""
    line = _Line()
    lay(line, Arrival((ToolEvent("bytes", b"0M!"),), since=2.0, at=2.03, earliest=2.01))
    assert line.calls == [("bytes", b"0M!", 2.03, 1200, pytest.approx(0.02))]


def test_a_byte_alone_in_its_read_is_its_packet_and_has_no_doubt():
    line = _Line()
    lay(line, Arrival((ToolEvent("bytes", b"0"),), since=2.0, at=2.03))
    assert line.calls == [("bytes", b"0", 2.03, 1200)]


def test_an_arrival_seen_empty_after_since_counts_its_span_from_then():
    assert Arrival((), since=1.0, at=1.05).unseen == pytest.approx(0.05)
    assert Arrival((), since=1.0, at=1.05, earliest=1.049).unseen == pytest.approx(0.001)
    assert Arrival((), since=1.0, at=1.05, earliest=0.5).unseen == pytest.approx(0.05)


def test_the_reader_notes_when_it_saw_the_socket_empty():
    """What a read returns came after the reader last saw nothing to read: a reader that
    looked just before bounds the merged span to that look."""
    client, server = _pair()
    try:
        opened = time.perf_counter()
        reader = ArrivalReader(server, time.perf_counter, opened=opened)
        reader.counts = False  # the look alone (test_idle_reader: what counting adds)
        with pytest.raises(TimeoutError):
            reader.read()  # nothing sent yet: it looked, and saw the socket empty
        looked = reader.empty_at
        assert opened < looked <= time.perf_counter()
        client.sendall(b"0M!")
        ((data, _since, at, _stamped),) = reader.read()
        assert data == b"0M!" and reader.empty_at == looked <= at + 1e-3
    finally:
        client.close()
        server.close()


def test_a_byte_alone_without_a_kernel_stamp_carries_the_span_of_its_late_read():
    """The kernel switches receive stamps on lazily: the first packets of a fresh socket
    often come without one (142 of 150 on a quiet machine), stamped as the read returned.
    Read 30 ms late, one byte alone was laid there with no doubt: R-7.0-06/-17 timed it
    from a made-up moment (the test above failed at +41.7 ms under load)."""
    line = _Line()
    lay(line, Arrival((ToolEvent("bytes", b"0"),), since=2.0, at=2.03, stamped=False))
    assert line.calls == [("bytes", b"0", 2.03, 1200, pytest.approx(0.03))]


def test_a_break_alone_without_a_kernel_stamp_carries_the_span_of_its_late_read():
    line = _Line()
    lay(line, Arrival((ToolEvent("break", on=False),), since=2.0, at=2.03, earliest=2.02,
                      stamped=False))  # fmt: skip
    assert line.calls == [("off", 2.03, pytest.approx(0.01))]
