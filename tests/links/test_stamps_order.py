"""Received frames keep the order they came in, however they are squeezed.

A reply whose bytes a stalled host (or sender) let pile up reaches the reader in bursts of
odd sizes. The stamps then cannot all be right: more bytes came than 1200 baud could carry
since the last ones, and the frames overlap. What must survive is their order, since the
view reads the wire by start: a real run on a loaded machine (bus_efficiency, eff11's
stalled run) had ``0,XH,mV,channel 65;JG<CR><LF>`` read as ``0,XH,mV,channel 65;<CR>JhG``
and R-4.2-02, R-4.2-03 and R-4.3-01 FAILed on text the sensor never sent."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.links.echo import EchoMode
from conformance.links.factory import open_real_link
from conformance.links.stamps import MAX_LEAD, chunk_frames
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, EventKind, to_wire_7e1


def _place(chunks: list[tuple[int, float]], floor: float = 0.0) -> list[tuple[float, float]]:
    """Every frame of chunks (count, arrival) read one after the other, as a link does."""
    frames: list[tuple[float, float]] = []
    for count, arrival in chunks:
        placed = chunk_frames(count, arrival, floor)
        frames += placed
        floor = placed[-1][1]
    return frames


def test_a_burst_after_single_bytes_does_not_start_before_them():
    # three bytes read one at a time at the same instant, then two together: before, the
    # pair's first frame started a whole character before the last single byte's
    frames = _place([(1, 1.0), (1, 1.0), (1, 1.0), (2, 1.0)], floor=1.0 - CHAR_TIME)
    starts = [start for start, _ in frames]
    assert starts == sorted(starts), starts
    assert frames[-1][1] <= 1.0 + MAX_LEAD + 1e-12


@given(
    st.lists(
        st.tuples(st.integers(1, 40), st.floats(0.0, 0.2, allow_nan=False)),
        min_size=1,
        max_size=30,
    )
)
def test_frames_start_in_the_order_they_came_and_lead_their_arrival_by_max_lead(chunks):
    at, timeline = 1.0, []
    for count, pause in chunks:
        at += pause  # the reads return in order, sometimes at once
        timeline.append((count, at))
    frames = _place(timeline)
    starts = [start for start, _ in frames]
    assert starts == sorted(starts)
    k = 0
    for count, arrival in timeline:
        k += count
        assert frames[k - 1][1] <= arrival + MAX_LEAD + 1e-9
    for start, end in frames:
        assert abs(end - start - CHAR_TIME) < 1e-12


@given(st.integers(1, 12), st.floats(0.0, 1.0, allow_nan=False))
def test_bytes_that_fit_stay_back_to_back_ending_at_their_arrival(count, spare):
    arrival = 2.0
    floor = arrival - count * CHAR_TIME - spare
    frames = chunk_frames(count, arrival, floor)
    assert abs(frames[-1][1] - arrival) < 1e-9
    for (_, end), (start, _) in zip(frames, frames[1:], strict=False):
        assert abs(start - end) < 1e-12


def test_a_reply_read_in_stalled_bursts_reads_as_it_was_sent():
    reply = "0,XH,mV,channel 65;JG\r\n"
    # the eff11 run's shape: a few bytes on time, then the rest in bursts of 1-3 bytes read
    # within a fraction of a millisecond of each other, 58 ms late
    sizes = [1, 1, 1, 1, 2, 1, 1, 1, 3, 1, 1, 2, 1, 1, 1, 1, 2, 1]
    assert sum(sizes) == len(reply)
    link = open_real_link("loop://", echo=EchoMode.OFF)
    try:
        at, k = 1.0, 0
        for n, size in enumerate(sizes):
            at += CHAR_TIME if n < 4 else 0.0002
            if n == 4:
                at += 0.058
            link._arrived(bytes(to_wire_7e1(ord(c)) for c in reply[k : k + size]), at)
            k += size
        chars = [e for e in link.transcript.events if e.kind is EventKind.CHAR and e.origin == DUT]
        read = "".join(chr(e.wire & 0x7F) for e in sorted(chars, key=lambda e: e.start))
        assert read == reply
    finally:
        link.close()
