"""From byte arrival stamps to wire events.

A host sees a received byte only after its stop bit, and usually later still: a USB adapter
batches bytes, a network adds its delay, a thread wakes late. What reaches the reader is a
chunk of bytes and the instant the read returned. The estimate made here is the latest
consistent with the bytes: the last byte of a chunk ended when the chunk arrived, the bytes
before it were back to back (a chunk read at once cannot reveal the gaps between them), and
no frame starts before the previous received frame ended, because one wire carries one
frame at a time. That last rule may push a chunk's frames past its arrival (the previous
chunk came late, this one on time), but never by more than ``MAX_LEAD``: more bytes than the
time since the previous ones could carry at 1200 baud (a flood, a device at the wrong rate,
bytes a stalled host or sender let pile up) end up overlapping, which is what the bit-rate
judge should then see. Overlapping, they still keep the order they came in: no frame starts
before the frame received before it, since the view reads the wire in the order of the
starts, and a reply whose characters were shuffled by the squeeze would be judged as text it
never was (a stall of 58 ms on a loaded machine made ``0,XH,mV,channel 65;`` read
``0,XH,mV,channel 65;<CR>JhG``). Whatever the adapter's latency hides goes into the link's
declared uncertainty, not into these numbers.
"""

from __future__ import annotations

from ..protocol.timing import CHAR_TIME

MAX_LEAD = 2 * CHAR_TIME  # s: how far the no-overlap rule may push frames past their arrival


def chunk_frames(
    count: int, arrival: float, floor: float, char_time: float = CHAR_TIME
) -> list[tuple[float, float]]:
    """(start, end) of ``count`` bytes read together at ``arrival``.

    ``floor`` is the end of the previous received frame (or the moment the link opened).
    """
    if count <= 0:
        return []
    first = max(arrival - count * char_time, floor)
    if first <= arrival + MAX_LEAD - count * char_time:
        return [(first + k * char_time, first + (k + 1) * char_time) for k in range(count)]
    # more than fits: the frames squeezed, in their order, between the previous frame's start
    # and the last start MAX_LEAD allows, overlapping each other and the previous frame
    after = floor - char_time
    last = max(after, arrival + MAX_LEAD - char_time)
    step = (last - after) / count
    starts = [after + (k + 1) * step for k in range(count)]
    return [(start, start + char_time) for start in starts]


def overlap(count: int, arrival: float, floor: float, char_time: float = CHAR_TIME) -> float:
    """How far (s) ``count`` bytes arriving at ``arrival`` would start before the previous
    frame ended, taken at face value: 0 for possible stamps, else the size of the artefact
    (a late stamp before, or an early one now) that :func:`chunk_frames` has to correct."""
    return max(0.0, floor - (arrival - count * char_time))
