"""The real-time line notes a stall of its own process (truth32): its thread came back more
than ``host_stall.STALL_MIN`` later than it planned (the end of a wait, the frame it spun for,
the step it began), or committed a frame late where no turn showed it (truth34: any frame
more than ``LATE_NOTICE`` late, however short the stall). A frame made late inside a noted
stall is the stall's; lateness outside every noted stall is left for the served line's
whole-run guard only where the line has no listener. Driven turn by turn on a clock the
test sets."""

from __future__ import annotations

from conformance.emulator_server.realtime import RealTimeLine
from conformance.sim.bus import Frame


class OneFrame:
    """A device with one frame to send at ``start``."""

    def __init__(self, start: float) -> None:
        self.frames = [Frame(start, 0x30)]

    def next_frame(self) -> Frame | None:
        return self.frames[0] if self.frames else None

    def pop_frame(self) -> Frame:
        return self.frames.pop(0)

    def on_char(self, wire: int, start: float, end: float) -> None:
        pass

    def on_break(self, start: float, end: float) -> None:
        pass


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def _line(start: float) -> tuple[RealTimeLine, Clock, list[float]]:
    clock, noted = Clock(), []
    line = RealTimeLine(OneFrame(start), lambda _b: None, clock=clock, on_stall=noted.append)
    return line, clock, noted


def test_a_turn_back_late_is_noted_and_the_frame_it_made_late_is_explained():
    line, clock, noted = _line(1.0)
    line._expected = 0.95  # a wait planned to end at 0.95 s
    clock.t = 1.10  # the thread came back 150 ms late
    line._back(clock.t)
    assert [round(s, 3) for s in noted] == [0.15]
    line._step()  # the frame due at 1.0 s went out 100 ms late: the stall's
    assert line.worst_lateness > 0.09
    assert line.unexplained_lateness == 0.0
    assert "1 stalls of this process noted" in line.timekeeping()


def test_a_frame_late_by_less_than_the_stall_minimum_is_noted_too():
    """truth34: the line's lateness outside its notes (3.0-28.7 ms in truth32's runs, 6.0 ms
    unpaused) was its thread's scheduling, under ``STALL_MIN``: left unexplained, it made the
    guard undecide the whole run. The turn back 5 ms late is no stall; the frame it made
    late is noted, so the judges hold what it covers and nothing is left unexplained."""
    line, clock, noted = _line(1.0)
    line._expected = 1.0
    clock.t = 1.005
    line._back(clock.t)
    assert noted == []  # a turn 5 ms late is ordinary scheduling
    line._step()
    assert [round(s, 3) for s in noted] == [0.005]
    assert line.unexplained_lateness == 0.0


def test_a_frame_within_the_late_notice_is_not_noted():
    line, clock, noted = _line(1.0)
    clock.t = 1.0015
    line._step()
    assert noted == [] and line.unexplained_lateness == 0.0


def test_a_frame_late_past_the_stall_minimum_where_no_turn_showed_it_is_a_stall():
    line, clock, noted = _line(1.0)
    clock.t = 1.2
    line._step()  # held up inside a step: no turn measured it, the frame's lateness does
    assert [round(s, 3) for s in noted] == [0.2]
    assert line.unexplained_lateness == 0.0


def test_a_line_without_a_listener_keeps_its_figures_as_before():
    clock = Clock()
    line = RealTimeLine(OneFrame(1.0), lambda _b: None, clock=clock)
    clock.t = 1.2
    line._back(clock.t)
    line._step()
    assert round(line.worst_lateness, 3) == 0.2
    assert round(line.unexplained_lateness, 3) == 0.2
    assert "stalls of this process" not in line.timekeeping()


class Breaks(OneFrame):
    """:class:`OneFrame` that keeps the breaks it hears, with the room the line gives them."""

    def __init__(self) -> None:
        super().__init__(99.0)
        self.breaks: list[tuple[float, float, float]] = []

    def on_break_within(self, start: float, end: float, room: float) -> None:
        self.breaks.append((start, end, room))


def test_a_break_laid_behind_a_burst_carries_the_shift_as_its_room():
    """truth34's paused external run: the recorder's bytes and its break came in one late
    burst; the line laid the break behind the bytes still on its wire, after its end had
    arrived: a 0.00 ms break, and R-7.0-02 and R-7.0-06 FAILed. Its place and length are
    known only to that shift: the room goes with it (the judges add it to the stamps')."""
    clock, device = Clock(), Breaks()
    line = RealTimeLine(device, lambda _b: None, clock=clock)
    line.tool_bytes(b"0D0!0D0!", at=1.0, doubt=0.0)  # 8 frames: the wire busy to 1.0667 s
    line.break_on(at=1.001)
    line.break_off(at=1.002)
    clock.t = 2.0
    for _ in range(20):
        line._step()
    start, end, room = device.breaks[0]
    assert end - start == 0.0 and room >= start - 1.002 > 0.06
    clean = Breaks()
    line = RealTimeLine(clean, lambda _b: None, clock=clock)
    line.break_on(at=1.0)
    line.break_off(at=1.013)
    for _ in range(5):
        line._step()
    assert clean.breaks == []  # a break laid where it came: no room, heard as before
