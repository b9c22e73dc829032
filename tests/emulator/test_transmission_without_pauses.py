"""Issue 22, matrix round 12: a transmission without pauses (every reply but a pausing
fault's) places its frames without a call of ``Transmission.held`` per frame, which is 0.0
there: the same floats as ``start + index * (char_time + gap) + held(index)``, a negative
zero included (adding 0.0 makes it 0.0, as adding held's 0.0 did)."""

from __future__ import annotations

import struct

import pytest

from conformance.emulator.replies import Reply, ReplyKind
from conformance.emulator.transmitter import Transmission

REPLY = Reply(ReplyKind.DATA, "0+1.25-3.5+17")


def _bits(x: float) -> bytes:
    return struct.pack("<d", x)  # tells -0.0 from 0.0


def _held_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    def refused(self: Transmission, index: int) -> float:
        if not self.pauses:
            raise AssertionError("held called for a transmission without pauses")
        return sum(extra for at, extra in self.pauses if 0 < at <= index)

    monkeypatch.setattr(Transmission, "held", refused)


@pytest.mark.parametrize(
    ("start", "gap", "char_time"),
    [
        (1.234567, 0.0, 8.33e-3),
        (0.0, 1.7e-3, 8.33e-3),
        (-0.0, 0.0, 8.33e-3),
        (-0.0, -9e-3, 8.33e-3),
        (57.579, 3e-3, 9.1e-3),
        (1e-9, 0.4e-3, 8.333333e-3),
    ],  # fmt: skip
)
def test_frames_without_pauses_are_placed_as_before_without_held(
    start: float, gap: float, char_time: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    _held_refused(monkeypatch)
    item = Transmission(REPLY, start, REPLY.wires(), gap, char_time=char_time)
    expected = [start + i * (char_time + gap) + 0.0 for i in range(len(item.wires))]
    assert [_bits(item.frame_start(i)) for i in range(len(item.wires))] == list(
        map(_bits, expected)
    )
    assert _bits(item.end) == _bits(expected[-1] + char_time)
    for sent in range(len(item.wires)):
        item.sent = sent
        got = list(item.rest())
        assert [_bits(s) for s, _, _ in got] == list(map(_bits, expected[sent:]))
        assert [(w, d) for _, w, d in got] == [(w, char_time) for w in item.wires[sent:]]


def test_frames_with_pauses_still_add_them(monkeypatch: pytest.MonkeyPatch) -> None:
    _held_refused(monkeypatch)
    item = Transmission(REPLY, 2.0, REPLY.wires(), 1e-3, pauses=((3, 0.004), (5, 0.002)))
    step = item.char_time + 1e-3
    held = [0.0, 0.0, 0.0, 0.004, 0.004, 0.004 + 0.002]
    for i, extra in enumerate(held):
        assert item.frame_start(i) == 2.0 + i * step + extra
    assert [s for s, _, _ in item.rest()][: len(held)] == [
        2.0 + i * step + extra for i, extra in enumerate(held)
    ]
