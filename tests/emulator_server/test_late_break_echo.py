"""The echo of a break comes back before the echo of the command that follows it, however
late the line's thread (or the server's read of the recorder's bytes) gets to it.

truth23/truth25: behind ``--echo --usb-latency 16`` on a loaded host the emulator delivered
the break's 0x00 after the echo of ``2I!`` (its delivery was placed when the line's thread
reached the stop-bit sample, by then behind the command's), the tool took the 0x00 for the
sensor's reply to a foreign address and FAILed R-4.0-01, R-4.2-02, R-4.2-03 and R-4.3-01. A
real interface reads the line in wire order. The line here runs on a hand-turned clock, no
thread: each step is what the thread does at that moment."""

from __future__ import annotations

import pytest

from conformance.emulator_server.bench import BenchModel
from conformance.emulator_server.realtime import RealTimeLine

from .test_bench import _Quiet


class _Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def _run_due(line: RealTimeLine, clock: _Clock, until: float) -> None:
    """Do every queued action due by ``until``, as the line's thread would, late or not."""
    while line._due and line._due[0].time <= until:
        clock.t = max(clock.t, line._due[0].time)
        line._step()


def _late_line(bench: BenchModel, lateness: float) -> list[int]:
    """A break (13 ms), 9 ms of marking and ``2I!``, all handed to the line ``lateness`` s
    after the break began (one late read of the recorder's stream); what the recorder hears
    back, in order."""
    clock = _Clock()
    heard: list[int] = []
    line = RealTimeLine(_Quiet(), heard.extend, clock=clock, bench=bench)
    clock.t = lateness
    line.break_on(at=0.0)
    line.break_off(at=0.013)
    line.tool_bytes(b"2I!", at=0.022)
    _run_due(line, clock, 1.0)
    return heard


@pytest.mark.parametrize(
    "bench",
    [
        BenchModel(echo=True),
        BenchModel(echo=True, usb_latency=16e-3),
        BenchModel(echo=True, jitter=2e-3, seed=5),
        BenchModel(echo=True, usb_latency=16e-3, jitter=2e-3, seed=7),
    ],
    ids=["echo", "usb16", "jitter2", "usb16-jitter2"],
)
@pytest.mark.parametrize("lateness", [0.0, 0.03, 0.06])
def test_the_break_echo_comes_back_before_the_command_echo(bench, lateness):
    assert _late_line(bench, lateness) == [0x00, *b"2I!"]


def test_a_short_pulse_still_reads_as_its_byte():
    """The echo placed at the break's start still reads the spacing's length when it is
    emitted: a pulse of 5 ms (6 bit times) reads as 0xE0, not as a break."""
    clock = _Clock()
    heard: list[int] = []
    line = RealTimeLine(_Quiet(), heard.extend, clock=clock, bench=BenchModel(echo=True))
    clock.t = 0.05
    line.break_on(at=0.0)
    line.break_off(at=0.005)
    _run_due(line, clock, 1.0)
    assert heard == [0xE0]


def test_an_echo_delivered_after_the_next_break_began_reads_its_own_spacing():
    """Behind a long latency the echo of a 5 ms pulse is emitted after a held break began:
    it still reads its own pulse (0xE0), not the break held now (whose own echo follows)."""
    clock = _Clock()
    heard: list[int] = []
    bench = BenchModel(echo=True, usb_latency=40e-3)
    line = RealTimeLine(_Quiet(), heard.extend, clock=clock, bench=bench)
    line.break_on(at=0.0)
    line.break_off(at=0.005)
    line.break_on(at=0.015)
    _run_due(line, clock, 0.045)
    assert heard == [0xE0, 0x00]
