"""A read waits past its limit for what its stamps could still count, not for the link's
latency on top of them (issue 22, usb12).

A byte's arrival stamp already carries the latency: its frame is placed ending at its arrival
or later, so a character stamped as started before the limit reached the host within a frame
(or a batch's frames) of it. Behind ``--echo --usb-latency 16`` the worst write-to-echo delay
(16.4 ms) stood in that grace, and every read that ran to its deadline (a command nobody
answered, a window for silence) waited 11 ms more than any stamp could count."""

from __future__ import annotations

import pytest

from conformance.links.echo import EchoMode
from conformance.links.factory import open_real_link
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import EventKind, to_wire_7e1


@pytest.fixture
def link():
    opened = open_real_link("loop://", echo=EchoMode.OFF)  # nothing is written: idle line
    yield opened
    opened.close()


def test_the_grace_is_a_frame_and_the_declared_floor_not_the_round_trip(link):
    floor = link.info.timing_uncertainty
    link.meter.round_trip.add(16.4e-3, "echo behind a 16 ms latency timer")
    assert link.latency_bound() == pytest.approx(16.4e-3)
    assert link.read_grace() == pytest.approx(CHAR_TIME + floor)


def test_bytes_that_came_several_to_a_stamp_widen_the_grace(link):
    link._arrived(bytes(to_wire_7e1(ord(c)) for c in "0\r\n"), 1.0)  # three at one stamp
    assert link.read_grace() == pytest.approx(3 * CHAR_TIME + link.info.timing_uncertainty)
    first = [e for e in link.transcript.events if e.kind is EventKind.CHAR][0]
    assert first.start >= 1.0 - 3 * CHAR_TIME - 1e-12  # never further before its arrival


def test_a_burst_of_bytes_each_under_its_own_stamp_does_not_widen_it(link):
    """Over plain RFC 2217 on a loaded host bytes came in bursts, each stamped alone: taken
    as batches they made the grace 3.3 ms longer, and R-7.0-14's probe after ``z!``'s
    silent read landed 100.8 ms after the reply it counts from, past standby, where its
    control went unanswered (INCONCLUSIVE where base-s66 PASSed)."""
    for k in range(3):
        link._arrived(bytes([to_wire_7e1(ord("0"))]), 1.0 + k * 1e-4)
    assert link.meter.batches.value > 0  # the meter saw the burst...
    assert link.read_grace() == pytest.approx(CHAR_TIME + link.info.timing_uncertainty)


@pytest.mark.parametrize("late_by", [0.2e-3, 0.6 * CHAR_TIME])
def test_a_character_stamped_before_the_limit_arrives_within_the_grace(link, late_by):
    """Whatever the latency, a lone byte whose stamp starts before the limit arrived less
    than a frame after it: the grace the read waits covers it."""
    limit = 2.0
    arrival = limit + late_by
    link._arrived(bytes([to_wire_7e1(ord("0"))]), arrival)
    (char,) = [e for e in link.transcript.events if e.kind is EventKind.CHAR]
    assert char.start < limit
    assert arrival <= limit + link.read_grace()
