"""The kit's own timing: frames and breaks rebuilt from a sketch's pin writes are where the
sketch wrote them, within 10 us (issue 25's bar; on the virtual clock they are exact), at the
sketch's own bit time (833, 800 and 867 us), with the marking between them kept.

The sketch (sketches/pin_pattern) logs on Serial the time and bit time of each character it
sends; the test plays the tool's side of the harness protocol itself, so what is compared is
the kit's rebuild and nothing else."""

from __future__ import annotations

import re

import pytest

from conformance.harness.channel import ChildChannel, HarnessError
from conformance.harness.protocol import Role, parse_plan
from tests.kit.conftest import SKETCHES

TOLERANCE_US = 10


def play(binary, role: Role) -> tuple[list[tuple[str, int, int, int]], str]:
    """Run the sketch as the tool would and collect its plans: (kind, start, end, wire)."""
    channel = ChildChannel(str(binary))
    try:
        assert channel.greet(role) == "pin_pattern"
        assert channel.version == 2
        message = "job 0 measure 0M!" if role is Role.RECORDER else "break 0 12000"
        now = 0 if role is Role.RECORDER else 12000
        plans = []
        for _ in range(100):
            plan = parse_plan(channel.ask(message), role, now, version=2)
            if plan.kind == "tx":
                end = plan.start + plan.duration
                plans.append(("tx", plan.start, end, plan.wire))
                message, now = f"sent {plan.start} {end} {plan.wire:02x}", end
            elif plan.kind == "brk":
                plans.append(("brk", plan.start, plan.end, 0))
                message, now = f"break {plan.start} {plan.end}", plan.end
            elif plan.kind == "wait":
                message, now = f"time {plan.start}", plan.start
            else:
                break
        channel.finish("bye")
        return plans, channel.stderr_tail()
    finally:
        channel.close()


def logged(stderr: str) -> tuple[list[tuple[int, int, int]], list[tuple[int, int]]]:
    frames = [tuple(map(int, m)) for m in re.findall(r"\] F (\d+) (\d+) (\d+)", stderr)]
    breaks = [tuple(map(int, m)) for m in re.findall(r"\] B (\d+) (\d+)", stderr)]
    return frames, breaks


@pytest.mark.parametrize(
    ("role", "defines"),
    [(Role.SENSOR, ()), (Role.SENSOR, ("PATTERN_BREAK",)), (Role.RECORDER, ("PATTERN_BREAK",))],
)
def test_frames_and_breaks_are_where_the_sketch_wrote_them(kit_build, role, defines):
    """A sensor's break too (the protocol's ``brk`` from a sensor): before, the kit stopped
    at it ("a sensor cannot send a break"), the tool's harness ERROR."""
    binary = kit_build(SKETCHES / "pin_pattern", defines=defines)
    plans, stderr = play(binary, role)
    frames, breaks = logged(stderr)
    assert len(frames) == 7 and len(breaks) == len(defines), stderr
    assert "cannot send a break" not in stderr
    sent = [p for p in plans if p[0] == "tx"]
    assert len(sent) == len(frames)
    for (_, start, end, wire), (t0, bit, wrote) in zip(sent, frames, strict=True):
        assert abs(start - t0) <= TOLERANCE_US  # the start bit's write
        assert abs((end - start) - 10 * bit) <= TOLERANCE_US  # ten of the sketch's own bits
        assert wire == wrote
    # the marking between characters is what the sketch held: 0, 1200 or 3000 us
    gaps = [b[1] - a[2] for a, b in zip(sent, sent[1:], strict=False)]
    assert [round(g / 100) * 100 for g in gaps] == [0, 1200, 0, 3000, 0, 0]
    assert all(abs(g - round(g / 100) * 100) <= TOLERANCE_US for g in gaps)
    held = [p for p in plans if p[0] == "brk"]
    assert len(held) == len(breaks)
    for (_, start, end, _), (b0, b1) in zip(held, breaks, strict=True):
        assert abs(start - b0) <= TOLERANCE_US and abs(end - b1) <= TOLERANCE_US
    if held:  # the first frame after the 9.1 ms of marking the sketch held
        assert abs(sent[0][1] - held[0][2] - 9100) <= TOLERANCE_US


def test_a_stuck_transmitter_stops_the_kit_with_a_message(kit_build):
    """Spacing held for 10 s of virtual time is a stuck line, not a break to wait out: the
    kit exits naming it (the tool's harness ERROR) instead of spinning until the reply
    timeout."""
    binary = kit_build(SKETCHES / "stuck_line")
    channel = ChildChannel(str(binary))
    try:
        channel.greet(Role.RECORDER)
        with pytest.raises(HarnessError, match="closed its output"):
            channel.ask("job 0 measure 0M!")
        assert "exit status 3" in channel.status()
        assert "held the line spacing since 0 us, 10 s" in channel.stderr_tail()
    finally:
        channel.close()


def test_a_pin_driven_before_it_became_the_data_pin_stops_the_kit(kit_build):
    """A sketch that breaks on pin 5 and only then attaches its interrupt there (EnviroDIY's
    library listens only after its first command): with no --pin the kit learned the data
    pin too late and kept the break off the line, so the tool heard nothing of a command a
    board sends (outside32: every job's first command of EnviroDIY's d_simple_logger, judged
    "never sent"). The kit now stops naming the pin; given the pin, the break goes out."""
    channel = ChildChannel(str(kit_build(SKETCHES / "late_data_pin")))
    try:
        channel.greet(Role.RECORDER)
        with pytest.raises(HarnessError, match="closed its output"):
            plan = parse_plan(channel.ask("job 0 measure 0M!"), Role.RECORDER, 0, version=2)
            while plan.kind == "wait":
                plan = parse_plan(channel.ask(f"time {plan.start}"), Role.RECORDER, plan.start)
        assert "exit status 3" in channel.status()
        assert "pin 5 drove the line spacing at 0 us" in channel.stderr_tail()
        assert "--pin 5" in channel.stderr_tail()
    finally:
        channel.close()
    channel = ChildChannel(str(kit_build(SKETCHES / "late_data_pin", defines=("KIT_DATA_PIN=5",))))
    try:
        channel.greet(Role.RECORDER)
        plan = parse_plan(channel.ask("job 0 measure 0M!"), Role.RECORDER, 0, version=2)
        assert plan.kind == "brk" and plan.start == 0
        assert 12300 <= plan.end <= 12300 + TOLERANCE_US
    finally:
        channel.close()


def test_a_break_timed_by_polling_micros_is_rebuilt(kit_build):
    """A sketch that ends its break when micros() says so, from loop(): held 12.5 ms (plus
    the loop's own microseconds), told as one brk, then done."""
    channel = ChildChannel(str(kit_build(SKETCHES / "polled_break")))
    try:
        channel.greet(Role.RECORDER)
        plan = parse_plan(channel.ask("job 0 measure 0M!"), Role.RECORDER, 0, version=2)
        if plan.kind == "wait":  # its first micros() call: 1 us past the job's time
            plan = parse_plan(channel.ask(f"time {plan.start}"), Role.RECORDER, plan.start)
        assert plan.kind == "brk" and plan.start <= 2
        assert 12500 <= plan.end - plan.start <= 12500 + TOLERANCE_US
        end = parse_plan(channel.ask(f"break {plan.start} {plan.end}"), Role.RECORDER, plan.end)
        assert end.kind == "done"
    finally:
        channel.close()


def test_a_break_begun_inside_a_reply_keeps_its_start_then_goes_out_whole(kit_build):
    """A sketch that breaks at the first edge of a reply (the twenty-fourth round's ATtiny
    logger): its break, begun inside the character just told, is planned from where it
    began (the protocol's one exception: the tool holds it back and marks it so); told the
    reply's next character instead, the break lies wholly inside the line's characters and
    goes out whole from there, 12.1 ms. Before: 'brk 1008333 1012101' (the start moved, the
    tool never told), then 'brk 1016666 1012101', a break ending before it starts."""
    channel = ChildChannel(str(kit_build(SKETCHES / "break_on_reply")))
    try:
        channel.greet(Role.RECORDER)
        plan = parse_plan(channel.ask("job 0 measure 0M!"), Role.RECORDER, 0, version=2)
        assert plan.kind == "idle"
        told = "char 1000000 1008333 30"
        plan = parse_plan(channel.ask(told), Role.RECORDER, 1008333, 1000000, version=2)
        assert plan.kind == "brk" and 1000000 <= plan.start <= 1000000 + TOLERANCE_US
        assert plan.end - plan.start == 12100
        told = "char 1008333 1016666 30"
        again = parse_plan(channel.ask(told), Role.RECORDER, 1016666, 1008333, version=2)
        assert (again.kind, again.start, again.end) == ("brk", 1016666, 1016666 + 12100)
    finally:
        channel.close()
