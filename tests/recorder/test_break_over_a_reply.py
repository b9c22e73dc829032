"""A recorder harness's break that a played sensor's reply runs on under (twenty-fourth outside
round, docs/kit.md: frankyn/SDI-12-ATTiny84a on the Arduino kit).

That firmware restarts at the first edge of a reply (its pin-change vector has no ISR) and
begins the break of its first command again while the sensor still talks. The kit sent the
break from the end of the reply's first character, where the sensor's next character began
too; the sim bus let the sensor go on under the break (its character ended 4.5 ms after the
break did) and the tool told the harness ``break START END``, but checked its answer against
the end of that character, which it had not told: the harness's ``wait END+20`` (its marking
after the break, in 20 us steps) was "not after now", a protocol ERROR that stopped the run.
A ``break`` is told at its END (docs/harness-protocol.md), and a character the line carried
under it is told next, as a ``char``, with no quiet promised past its start.
"""

from __future__ import annotations

import json
import sys

from conformance.conduct import run_into
from conformance.harness import protocol as proto
from conformance.harness.protocol import BATCH, Plan, PlanKind
from conformance.recorder.harness_driver import HarnessRecorder, _quiet
from conformance.recorder.job_time import JobBudget
from conformance.sim.bus import SimBus
from conformance.transcript import TOOL, Event, EventKind, Transcript
from conformance.verdicts import Verdict
from tests.support.harness_script import PRELUDE

#: A version-1 recorder harness: its job's first command after a 12.5 ms break and 8.4 ms of
#: marking; at the reply's first character it begins its break again from that character's
#: end (as the firmware's restart does, 12.1 ms from where it began driving), then marks in
#: 20 us steps from the break's end, as told, and is done at the next message after them.
_BREAKS_OVER_THE_REPLY = (
    PRELUDE
    + r"""
cmd, sent, at, phase = "", 0, 0, ""
told = []
for line in sys.stdin:
    word, *f = line.split()
    if word == "bye":
        break
    told.append(word)
    if word == "hello":
        say("hello 1 breaks-over-the-reply")
    elif word == "job":
        cmd, phase = f[2], "brk"
        say(f"brk {f[0]} {int(f[0]) + 12500}")
    elif phase == "brk":
        phase, sent, at = "tx", 0, int(f[1]) + 8400
        say(f"tx {at} {wire(cmd[0]):02x}")
    elif phase == "tx" and word == "sent":
        sent, at = sent + 1, int(f[1])
        if sent < len(cmd):
            say(f"tx {at} {wire(cmd[sent]):02x}")
        else:
            phase = "listen"
            say(f"wait {at + 1000000}")
    elif phase == "listen" and word == "char":
        phase = "again"
        say(f"brk {f[1]} {int(f[0]) + 12120}")
    elif phase == "again" and word == "break":
        phase = "marking"
        say(f"wait {int(f[1]) + 20}")
    elif phase == "marking":
        sys.stderr.write("told after the break: " + " ".join(told[-3:]) + "\n")
        say("done")
    else:
        say("idle")
"""
)


def test_a_break_a_reply_runs_on_under_is_told_at_its_end(tmp_path):
    """ERROR 'wait time is not after now' on the tree before: the answer to the break was
    checked against the end of the sensor's character that went on under it."""
    harness = tmp_path / "breaks.py"
    harness.write_text(_BREAKS_OVER_THE_REPLY)
    out = tmp_path / "run"
    found = run_into(
        out, f"exec:{sys.executable} {harness}", "recorder", keyword="test_breaks", version="1.3"
    )
    errors = [r for r in found["requirements"] if r["verdict"] == Verdict.ERROR.value]
    assert not errors, errors[0]["findings"][0]["detail"]
    events = [json.loads(line) for line in (out / "transcript.jsonl").read_text().splitlines()]
    breaks = [e for e in events if e["kind"] == "break" and e["origin"] == TOOL]
    under = [e for e in events if e["kind"] == "char" and e["origin"] != TOOL]
    over = [
        (b, c)
        for b in breaks
        for c in under
        if abs(c["start"] - b["start"]) < 1e-6 and c["end"] > b["end"] + 1e-3
    ]
    assert over, "no break with a sensor's character going on under it: the case is not met"


class _Told:
    """A batch harness that records what it is told (and at what now), then is done."""

    features = frozenset({BATCH})

    def __init__(self) -> None:
        self.told: list[tuple[str, float]] = []

    def plan(self, message: str, role, now: float, since: float | None = None) -> Plan:
        self.told.append((message, now))
        if len(self.told) == 1:
            return Plan(PlanKind.WAIT, start=round(now * 1e6) + 20)
        return Plan(PlanKind.DONE)


class _ReplyRunsOn:
    """A link whose break a device's character goes on under: the character began at the
    break's start and ends 4.5 ms after the break, committed (queued to be received) while
    the break was sent, the link's clock at its end, as :meth:`SimBus.tool_break` leaves it."""

    def __init__(self) -> None:
        self.transcript = Transcript()
        self.clock = 1.0
        self.queued: list[Event] = []

    def now(self) -> float:
        return self.clock

    def receive(self, deadline, until=None, idle=None):
        if self.queued:
            return [self.queued.pop(0)]
        self.clock = max(self.clock, deadline)
        return []

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        start = self.clock
        made = self.transcript.add(Event(EventKind.BREAK, TOOL, start, start + duration))
        char = self.transcript.add(Event(EventKind.CHAR, "dut", start, made.end + 0.0045, 0xB0))
        self.queued.append(char)
        self.clock = char.end
        return made


def test_the_break_is_told_at_its_end_and_the_character_under_it_next():
    link, channel = _ReplyRunsOn(), _Told()
    HarnessRecorder("exec:none")._drive(
        channel, Plan(PlanKind.BRK, start=1_000_000, end=1_012_100), link, JobBudget(60, "")
    )
    (brk, brk_now), (char, char_now) = channel.told
    assert brk.split()[:3] == ["break", "1000000", "1012100"]
    assert brk_now == 1.0121  # its END, not the end of the character under it
    assert char.split()[:4] == ["char", "1000000", "1016600", "b0"]
    assert abs(char_now - 1.0166) < 1e-9


class _OnBus:
    """The job's link in front of an (empty) sim bus, its clock where a character that went
    on under a break left it."""

    def __init__(self, bus: SimBus) -> None:
        self.bus = bus

    def now(self) -> float:
        return self.bus.clock.now


def test_no_quiet_is_promised_past_a_character_not_yet_told():
    """With nothing planned the tool promised the line quiet up to the job's cut, though the
    character under the break was on the line, untold: a batch harness would run on past
    its start (the kit feeds a character's edges at their times only while it is behind)."""
    bus = SimBus()
    bus.clock.now = 1.0166
    message = proto.line_break(1.0, 1.0121)
    assert _quiet(_Told(), _OnBus(bus), 60.0, message) == f"{message} 60000000"
    bus.rx.append(Event(EventKind.CHAR, "dut", 1.0, 1.0166, 0xB0))
    assert _quiet(_Told(), _OnBus(bus), 60.0, message) == message
