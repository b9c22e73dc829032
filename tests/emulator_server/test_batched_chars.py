"""Command characters the served line reads together (R-7.0-06, R-7.0-13, R-7.0-17).

A recorder's bytes sent apart reach the server as packets with their own kernel stamps,
unless its reader is late (a loaded host): then the kernel merges the packets it holds into
one, under the later stamp, and '0', 20 ms, 'I!' reads as '0I!' stamped at the 'I!'. The
line lays the three back to back there: gaps of 0 ms and a start 20 ms late that no one
measured. Before, those characters carried the run's 5 ms and were judged from the made-up
times: R-7.0-06 PASSed a 2 ms marking (false PASS), R-7.0-17 FAILed a command sent 75 ms
after the line went quiet (false FAIL). Here the reader is made late on purpose (no load
needed): the characters now carry the span since the reader last saw its socket empty,
and the judges say INCONCLUSIVE.
"""

from __future__ import annotations

import time

import pytest

from conformance.emulator_server import servers
from conformance.judges.recorder.breaks import judge_break_rules, judge_breaks
from conformance.protocol.timing import CHAR_TIME
from conformance.recorder.served_line import ServedLine, ServeSpec
from conformance.transcript import EventKind
from conformance.verdicts import Verdict
from conformance.view.segments import read_view

from .test_batched_reads import BREAK_OFF, BREAK_ON, U, command, playing


class _StallingReader(servers.ArrivalReader):
    """Reads as the served line's reader does, but once it has read ``AFTER`` it gets the CPU
    back only ``STALL`` s later, as a loaded host's reader may."""

    AFTER = BREAK_OFF
    STALL = 0.0
    stalled = False

    def read(self):  # type: ignore[override]
        groups = super().read()
        if groups and not self.stalled and self.AFTER in b"".join(g[0] for g in groups):
            type(self).stalled = True
            time.sleep(self.STALL)
        return groups


def served(monkeypatch, after: bytes, stall: float, *steps: bytes | float) -> list:
    """Send ``steps`` (bytes: one ``sendall``; float: a pause in s) to a served line of no
    sensors whose reader stalls ``stall`` s once it has read ``after``."""
    monkeypatch.setattr(_StallingReader, "AFTER", after)
    monkeypatch.setattr(_StallingReader, "STALL", stall)
    monkeypatch.setattr(_StallingReader, "stalled", False)
    monkeypatch.setattr(servers, "ArrivalReader", _StallingReader)
    line = ServedLine(ServeSpec("127.0.0.1", 0))
    try:
        with playing(line.server.address, steps):
            time.sleep(stall + 0.1)
        return list(line.transcript.events)
    finally:
        line.close()


def by_id(findings):
    return {f.requirement: f for f in findings}


@pytest.mark.realtime  # real sends and sleeps 2-150 ms apart
def test_r_7_0_06_a_command_sent_in_pieces_and_read_late_does_not_pass_a_2_ms_marking(
    monkeypatch,
):
    """Break-off, 2 ms, '0', 20 ms, 'I!': a 2 ms marking (and a 20 ms gap in the command).
    Read late, '0I!' is stamped 22 ms after the break-off: it PASSed R-7.0-06."""
    events = served(
        monkeypatch,
        BREAK_OFF,
        0.060,
        BREAK_ON,
        0.030,
        BREAK_OFF,
        0.002,
        command("0"),
        0.020,
        command("I!"),
    )
    chars = [e for e in events if e.kind is EventKind.CHAR]
    assert len(chars) == 3, events
    if chars[1].start - chars[0].start > CHAR_TIME + 2e-3:
        pytest.skip("the kernel kept the two sends apart (its reader read before the stall)")
    found = by_id(judge_breaks(read_view(events), U))
    assert found["R-7.0-06"].verdict is Verdict.INCONCLUSIVE, found["R-7.0-06"]
    # merged: laid back to back, each carrying the span it may have been sent in
    assert all(c.uncertainty >= U + 0.015 for c in chars), chars


@pytest.mark.realtime  # real sends and sleeps 30-200 ms apart
def test_r_7_0_17_a_command_sent_in_pieces_and_read_late_does_not_fail_its_87_ms(monkeypatch):
    """'0I!' after a break; 100 ms later '0', 30 ms later 'I!' without a break: the line was
    quiet 75 ms before the '0' (its '0I!' ends 25 ms after it was sent). Read late, the
    second '0I!' is stamped 130 ms after the first: it FAILed R-7.0-17 on 105 ms ± 5 ms."""
    first = command("0I!")
    events = served(
        monkeypatch,
        first,
        0.200,
        BREAK_ON,
        0.030,
        BREAK_OFF,
        0.030,
        first,
        0.100,
        command("0"),
        0.030,
        command("I!"),
    )
    chars = [e for e in events if e.kind is EventKind.CHAR]
    assert len(chars) == 6, events
    if chars[4].start - chars[3].start > CHAR_TIME + 2e-3:
        pytest.skip("the kernel kept the two sends apart (its reader read before the stall)")
    found = by_id(judge_break_rules(read_view(events), U))
    assert found["R-7.0-17"].verdict is Verdict.INCONCLUSIVE, found["R-7.0-17"]
