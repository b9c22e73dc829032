"""The harness protocol checker (conformance.harness.protocol): each malformed reply is
refused with its reason and the offending line; well-formed ones parse to the plan they say."""

from __future__ import annotations

import pytest

from conformance.harness import protocol as proto
from conformance.harness.protocol import HarnessProtocolError, Plan, PlanKind, Role


@pytest.mark.parametrize(
    ("text", "role", "plan"),
    [
        ("tx 6000 b1", Role.SENSOR, Plan(PlanKind.TX, start=6000, wire=0xB1)),
        ("tx 5010 8D", Role.SENSOR, Plan(PlanKind.TX, start=5010, wire=0x8D)),
        ("tx 5000 30", Role.SENSOR, Plan(PlanKind.TX, start=5000, wire=0x30)),
        ("tx 0 30", Role.SENSOR, Plan(PlanKind.TX, start=0, wire=0x30)),  # before now: ASAP
        # within the rounding slack of whole-microsecond frame times: taken as now
        ("brk 4998 17500", Role.RECORDER, Plan(PlanKind.BRK, start=4998, end=17500)),
        ("wait 5001", Role.SENSOR, Plan(PlanKind.WAIT, start=5001)),
        ("idle", Role.SENSOR, Plan(PlanKind.IDLE)),
        ("brk 5000 17500", Role.RECORDER, Plan(PlanKind.BRK, start=5000, end=17500)),
        ("done", Role.RECORDER, Plan(PlanKind.DONE)),
        # a sensor that holds the line spacing before its reply (was "recorder harnesses
        # only", an ERROR: the extension leaves every harness that worked unchanged)
        ("brk 6000 17500", Role.SENSOR, Plan(PlanKind.BRK, start=6000, end=17500)),
    ],
)
def test_well_formed_plans(text, role, plan):
    assert proto.parse_plan(text, role, now=5000) == plan


@pytest.mark.parametrize(
    ("text", "role", "reason"),
    [
        ("transmit 100 30", Role.SENSOR, "unknown reply"),
        ("", Role.SENSOR, "unknown reply"),
        ("TX 100 30", Role.SENSOR, "unknown reply"),
        ("tx 100", Role.SENSOR, "takes 2 field(s)"),
        ("tx 100 30 31", Role.SENSOR, "takes 2 field(s)"),
        ("tx  100 30", Role.SENSOR, "takes 2 field(s)"),
        ("idle now", Role.SENSOR, "takes 0 field(s)"),
        ("wait", Role.SENSOR, "takes 1 field(s)"),
        ("tx 1.5 30", Role.SENSOR, "not a whole number of microseconds"),
        ("tx -5 30", Role.SENSOR, "not a whole number of microseconds"),
        ("tx 0x10 30", Role.SENSOR, "not a whole number of microseconds"),
        ("tx 1000000000001 30", Role.SENSOR, "beyond 10^12"),
        ("tx 6000 3", Role.SENSOR, "not two hex digits"),
        ("tx 6000 130", Role.SENSOR, "not two hex digits"),
        ("tx 6000 zz", Role.SENSOR, "not two hex digits"),
        # a break starting already past is the harness's mistake, never "now" behind its back
        ("brk 0 16500", Role.RECORDER, "5000 us before now (5000 us): the tool cannot send in"),
        ("brk 4997 16500", Role.RECORDER, "3 us before now (5000 us)"),
        ("brk 4000 16500", Role.RECORDER, "1000 us before now"),
        ("wait 5000", Role.SENSOR, "not after now"),
        ("wait 10", Role.SENSOR, "not after now"),
        # a sensor's break is held to the clock as a recorder's is
        ("brk 4000 16500", Role.SENSOR, "1000 us before now"),
        ("brk 6000 6000", Role.SENSOR, "ends before it starts"),
        ("done", Role.SENSOR, "recorder harnesses only"),
        ("brk 6000 6000", Role.RECORDER, "ends before it starts"),
        ("brk 0 4000", Role.RECORDER, "5000 us before now"),
        ("brk 6000", Role.RECORDER, "takes 2 field(s)"),
    ],
)
def test_malformed_plans_are_refused_with_the_line(text, role, reason):
    with pytest.raises(HarnessProtocolError) as caught:
        proto.parse_plan(text, role, now=5000)
    assert reason in caught.value.reason
    assert caught.value.line == text
    assert repr(text) in str(caught.value)


@pytest.mark.parametrize(
    ("raw", "reason"),
    [
        (b"x" * 201, "longer than 200"),
        (b"tx 100 30\x00", "not printable ASCII"),
        (b"tx 100 \xb1", "not printable ASCII"),
        (b"idle\tnow", "not printable ASCII"),
    ],
)
def test_bad_lines_are_refused(raw, reason):
    with pytest.raises(HarnessProtocolError) as caught:
        proto.check_line(raw)
    assert reason in caught.value.reason


def test_a_carriage_return_before_the_newline_is_accepted():
    assert proto.check_line(b"idle\r") == "idle"


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("hi 1", "expected 'hello 1"),
        ("hello", "another protocol version"),
        ("hello 3 future", "another protocol version"),
        ("idle", "expected 'hello 1"),
    ],
)
def test_bad_hello_is_refused(text, reason):
    with pytest.raises(HarnessProtocolError) as caught:
        proto.parse_hello(text)
    assert reason in caught.value.reason


def test_hello_gives_the_harness_name():
    assert proto.parse_hello("hello 1 my sensor v2") == "my sensor v2"
    assert proto.parse_hello("hello 1") == ""


def test_the_tools_messages():
    assert proto.hello(Role.SENSOR) == "hello 1 sensor"
    assert proto.job(1.5, "measure", ("0M!", "1M!")) == "job 1500000 measure 0M! 1M!"
    assert proto.line_break(0.0, 0.0125) == "break 0 12500"
    assert proto.heard(0xB1, 0.020333333, 0.028666667) == "char 20333 28667 b1"
    assert proto.sent(0x0A, 1.0, 1.008333333) == "sent 1000000 1008333 0a"
    assert proto.time_is(2.25) == "time 2250000"


def test_a_plan_held_back_by_the_frame_just_reported_may_repeat_its_start():
    """A char is told after its stop bit: a recorder harness that planned brk 5200 before
    hearing of a char sent 5000..13333 answers that char (now 13333) with the same plan."""
    plan = proto.parse_plan("brk 5200 20000", Role.RECORDER, now=13333, since=5000)
    assert plan == Plan(PlanKind.BRK, start=5200, end=20000)
    with pytest.raises(HarnessProtocolError, match="before now"):
        proto.parse_plan("brk 4000 20000", Role.RECORDER, now=13333, since=5000)
    with pytest.raises(HarnessProtocolError, match="before now"):
        proto.parse_plan("brk 5200 20000", Role.RECORDER, now=13333)  # after sent/time: no


# -- version 2 (the firmware kits): frame lengths, and no tx in the past ---------------------


def test_a_harness_may_answer_version_2():
    assert proto.parse_hello_version("hello 2 my-sketch") == ("my-sketch", 2)
    assert proto.parse_hello_version("hello 1") == ("", 1)


def test_a_version_2_tx_carries_its_frame_length():
    plan = proto.parse_plan("tx 6000 30 8000", Role.SENSOR, now=5000, version=2)
    assert (plan.kind, plan.start, plan.wire, plan.duration) == (PlanKind.TX, 6000, 0x30, 8000)
    assert proto.parse_plan("tx 6000 30", Role.SENSOR, now=5000, version=2).duration == 0
    with pytest.raises(HarnessProtocolError, match="takes 2 field"):
        proto.parse_plan("tx 6000 30 8000", Role.SENSOR, now=5000)  # version 1: three fields


@pytest.mark.parametrize("duration", ["5555", "12501", "8.3", "833"])
def test_a_frame_length_outside_800_to_1800_baud_is_refused(duration):
    with pytest.raises(HarnessProtocolError):
        proto.parse_plan(f"tx 6000 30 {duration}", Role.SENSOR, now=5000, version=2)


def test_a_version_2_tx_in_the_past_is_a_harness_error():
    """Version 1 starts it now ("as soon as possible"); version 2 holds the harness to the
    clock, as brk is: the line is named, the device is never judged for it."""
    assert proto.parse_plan("tx 4000 30", Role.SENSOR, now=5000).start == 4000  # v1: ASAP
    with pytest.raises(HarnessProtocolError, match="1000 us before now"):
        proto.parse_plan("tx 4000 30 8330", Role.SENSOR, now=5000, version=2)
    # within the rounding slack it is now; the plan it had, repeated unchanged after a
    # reported frame that began before it, is taken (it goes out when the line is free)
    assert proto.parse_plan("tx 4999 30", Role.SENSOR, now=5000, version=2).start == 5000
    had = Plan(PlanKind.TX, start=4200, wire=0x30)
    late = proto.parse_plan(
        "tx 4200 30 8330", Role.SENSOR, now=13333, since=4000, version=2, previous=had
    )
    assert late.start == 13333
    # a new plan inside the frame just reported transmits before the line is idle
    with pytest.raises(HarnessProtocolError, match="wait for the line to be idle"):
        proto.parse_plan("tx 4200 30 8330", Role.SENSOR, now=13333, since=4000, version=2)


@pytest.mark.parametrize("role", [Role.SENSOR, Role.RECORDER])
def test_a_wait_beyond_10_12_us_is_a_long_sleep_not_a_harness_error_r_7_2_01(role):
    """The twenty-second round's logger (davemortek/stm32-sdi-12) reads ttt from a reply that
    never came, ``(response[1] - 48) * 100000 + ...`` into a uint32_t: a HAL_Delay of
    4289639296 ms, ``wait 4289644352000``. The run stopped "time beyond 10^12 us (units
    wrong?)", every later case ERROR, on a harness that said truly what its firmware does. A
    ``wait`` only promises nothing before T (the job's budget or the next event comes first);
    a ``tx``/``brk`` time that far out is still a harness counting wrong."""
    huge = 4289644352000
    assert proto.parse_plan(f"wait {huge}", role, now=5000) == Plan(PlanKind.WAIT, start=huge)
    with pytest.raises(HarnessProtocolError, match="beyond 10"):
        proto.parse_plan(f"tx {huge} 30", role, now=5000)
    with pytest.raises(HarnessProtocolError, match="beyond 10"):
        proto.parse_plan(f"brk 5000 {huge}", Role.RECORDER, now=5000)
