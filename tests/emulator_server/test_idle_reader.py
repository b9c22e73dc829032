"""A served line's reader on an idle socket (:class:`~conformance.emulator_server.servers.
ArrivalReader`): where the kernel counts the segments it received, the reader need not look
at the socket every millisecond to know how long it lay empty. rt2 looked every 1 ms (3 % of
a core per connected line, idle or not); a segment that came alone to an empty socket is
known to have come at its own stamp, however late the reader woke."""

from __future__ import annotations

import socket
import threading
import time

import pytest

from conformance.emulator_server import servers
from conformance.emulator_server.arrivals import Arrival, ToolEvent
from conformance.emulator_server.servers import ACTIVE_WINDOW, RECV_POLL, ArrivalReader
from tests.conftest import BUSY
from tests.support.own_time import own_time


def _pair() -> tuple[socket.socket, socket.socket]:
    listener = socket.create_server(("127.0.0.1", 0))
    ArrivalReader.ask_for_stamps(listener)
    with listener:
        client = socket.create_connection(listener.getsockname()[:2])
        server, _ = listener.accept()
    client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    server.settimeout(0.5)
    return client, server


def _counting_reader(server: socket.socket) -> ArrivalReader:
    reader = ArrivalReader(server, time.perf_counter, opened=time.perf_counter())
    if not reader.counts:
        pytest.skip("the kernel gives no receive stamps or segment counts here")
    return reader


def _stamped_once(client: socket.socket, reader: ArrivalReader) -> None:
    """Until the kernel stamps this socket's packets (it switches stamping on lazily)."""
    for _ in range(50):
        client.sendall(b"w")
        groups = reader.read()
        assert groups is not None
        if all(g[3] for g in groups):
            return
        time.sleep(0.01)
    pytest.skip("the kernel did not stamp the packets")


def _looked_empty(reader: ArrivalReader) -> float:
    """A read that finds nothing: the reader saw the socket empty; when (before the look)."""
    before = time.perf_counter()
    with pytest.raises(TimeoutError):
        reader.read()
    assert reader.empty_at >= before
    return reader.empty_at


def test_r_7_0_13_a_segment_alone_read_late_came_to_an_empty_socket_at_its_stamp():
    """'0M!' in one segment, read 30 ms after the reader last looked: the kernel counted one
    segment since, so its three bytes came together at its stamp, no span before it (the
    look-only reader gave them the 30 ms since its look as their doubt)."""
    client, server = _pair()
    try:
        reader = _counting_reader(server)
        _stamped_once(client, reader)
        looked = _looked_empty(reader)
        time.sleep(0.030)
        client.sendall(b"0M!")
        sent = time.perf_counter()
        time.sleep(0.030)  # the reader wakes late
        ((data, since, at, stamped),) = reader.read()
        assert (data, stamped) == (b"0M!", True)
        assert abs(at - sent) < 0.010, (at - sent) * 1e3
        assert reader.empty_at == at and at - looked > 0.025
        arrival = Arrival((ToolEvent("bytes", data),), since, at, reader.empty_at)
        assert arrival.unseen == 0.0
    finally:
        client.close()
        server.close()


def test_r_7_0_13_segments_the_kernel_may_have_merged_keep_the_look(monkeypatch):
    """Two segments counted since the look and one group read: the kernel merged them under
    the later stamp, the first may have come any time after the look, and empty_at stays
    there (the span is the characters' doubt, arrivals.char_doubt)."""
    client, server = _pair()
    try:
        reader = _counting_reader(server)
        _stamped_once(client, reader)
        looked = _looked_empty(reader)
        counted = reader.counted
        assert counted is not None
        client.sendall(b"0M!")
        monkeypatch.setattr(servers, "data_segments_in", lambda sock: counted + 2)
        ((_data, _since, at, _stamped),) = reader.read()
        assert reader.empty_at == looked < at
        assert reader.counted is None  # counted again only at the next empty look
    finally:
        client.close()
        server.close()


def test_segments_counted_before_the_look_are_not_counted_as_new():
    """A read that found bytes already waiting saw no empty socket: nothing to count from,
    and the look before stays the bound."""
    client, server = _pair()
    try:
        reader = _counting_reader(server)
        _stamped_once(client, reader)
        looked = _looked_empty(reader)
        client.sendall(b"0")
        time.sleep(0.005)
        client.sendall(b"M!")
        time.sleep(0.005)
        got = reader.read()
        assert got is not None
        first_at = got[0][2]
        # the two sends are two segments: either two groups (empty until the first) or
        # merged into one (the look stays); never empty until a merged group's stamp
        assert reader.empty_at in (looked, first_at)
        if len(got) == 1:
            assert reader.empty_at == looked
    finally:
        client.close()
        server.close()


def test_an_idle_line_waits_in_select_instead_of_looking_every_millisecond():
    """Idle for ACTIVE_WINDOW, a read blocks up to RECV_POLL (rt2: 1 ms, so about 1,000
    looks a second per idle connected line); a line that just heard the recorder still
    looks every EMPTY_POLL."""
    client, server = _pair()
    try:
        reader = _counting_reader(server)
        reader.since = time.perf_counter() - 2 * ACTIVE_WINDOW
        start = time.perf_counter()
        with pytest.raises(TimeoutError):
            reader.read()
        assert time.perf_counter() - start >= RECV_POLL * 0.9
        assert reader.wait(reader.since + ACTIVE_WINDOW / 2) == servers.EMPTY_POLL
    finally:
        client.close()
        server.close()


#: s: the byte is sent this long into the reader's wait
SEND_AT = 0.030


def test_an_idle_reader_wakes_at_once_for_a_byte():
    """Blocking does not delay what comes: a byte sent 30 ms into the reader's wait wakes
    it then, and the byte keeps its kernel stamp.

    Timed as the reader's own time (the wall less its thread's queueing for a CPU,
    tests/support/own_time.py) from the send: at nice 19 beside CI's other sessions the
    wall failed with nothing wrong. A reader that slept out its whole RECV_POLL wakes at
    least RECV_POLL - SEND_AT after the send; when the sending thread itself woke so late
    that this no longer tells the two apart, the machine was too busy and the test skips."""
    client, server = _pair()
    try:
        reader = _counting_reader(server)
        _stamped_once(client, reader)
        reader.since = time.perf_counter() - 2 * ACTIVE_WINDOW
        sent: list[tuple[float, float]] = []

        def send() -> None:
            before = time.perf_counter()
            client.sendall(b"0")
            sent.append((before, time.perf_counter()))

        timer = threading.Timer(SEND_AT, send)
        start = time.perf_counter()
        timer.start()
        with own_time() as took:
            ((data, _since, at, _stamped),) = reader.read()
        woke = time.perf_counter()
        timer.join()
        (before, after) = sent[0]
        assert data == b"0"
        late = before - start - SEND_AT
        if late > (RECV_POLL - 2 * SEND_AT) / 2:  # the send no longer halfway to a slept-out poll
            pytest.skip(f"{BUSY}: the byte was sent {late * 1e3:.0f} ms late")
        # woken by the byte: well before a slept-out poll would have ended after it
        assert woke - after - took.queued < (RECV_POLL - SEND_AT) / 2, (woke - after, took)
        assert before - 0.010 < at < after + 0.010  # its kernel stamp, not the read's time
    finally:
        client.close()
        server.close()
