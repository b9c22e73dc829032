"""A received character cannot have ended on the wire after the host had it (issue 22, usb12).

Behind a 16 ms latency timer a reply reaches the host two characters a tick: 16.67 ms of
frames every 16 ms, so the no-overlap rule of :func:`~conformance.links.stamps.chunk_frames`
places each batch after the one before and the reply's last character ends up stamped past
its arrival. :meth:`SerialLink.received_by` gives the arrival for such a frame, the stamp's
end otherwise; the engine counts a turnaround that needs no look from it."""

from __future__ import annotations

import pytest

from conformance.links.echo import EchoMode
from conformance.links.factory import open_real_link
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import EventKind, to_wire_7e1

TICK = 16e-3


def _reply_in_ticks(text: str):
    """A loop:// link that received ``text`` as a 16 ms latency timer hands it over: every
    character at the first tick after its stop bit, those of one tick together."""
    link = open_real_link("loop://", echo=EchoMode.OFF)  # nothing is written: the line is idle
    ends = [1.0 + (k + 1) * CHAR_TIME for k in range(len(text))]
    ticks: dict[float, bytes] = {}
    for char, end in zip(text, ends, strict=True):
        tick = round((int(end / TICK) + 1) * TICK, 9)
        ticks[tick] = ticks.get(tick, b"") + bytes([to_wire_7e1(ord(char))])
    for tick, data in ticks.items():
        link._arrived(data, tick)
    return link, ends, max(ticks)


def test_a_frame_placed_past_its_arrival_was_received_by_the_arrival():
    link, ends, last_tick = _reply_in_ticks("014MAKER   MODEL 1.0\r\n")
    try:
        lf = [e for e in link.transcript.events if e.kind is EventKind.CHAR][-1]
        assert lf.end > last_tick  # the stamp lies past the arrival...
        assert link.received_by(lf.end) == pytest.approx(last_tick)  # ...the wire did not
        assert ends[-1] <= link.received_by(lf.end)  # never before the real stop bit
    finally:
        link.close()


def test_a_frame_stamped_at_its_arrival_keeps_its_end():
    link = open_real_link("loop://", echo=EchoMode.OFF)
    try:
        link._arrived(bytes([to_wire_7e1(ord("0"))]), 1.0)
        link._arrived(bytes([to_wire_7e1(ord("\r"))]), 1.0 + 2 * CHAR_TIME)
        last = [e for e in link.transcript.events if e.kind is EventKind.CHAR][-1]
        assert link.received_by(last.end) == last.end == pytest.approx(1.0 + 2 * CHAR_TIME)
        assert link.received_by(0.5) == 0.5  # nothing known of it: its own end
    finally:
        link.close()


def test_only_the_latest_pushed_frames_are_kept():
    from conformance.links.serial_link import PUSHED_KEPT

    link, _ends, _tick = _reply_in_ticks("0" + "+1.234" * 30 + "\r\n")
    try:
        assert 0 < len(link._pushed) <= PUSHED_KEPT
    finally:
        link.close()
