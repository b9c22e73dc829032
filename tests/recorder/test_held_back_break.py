"""A recorder harness's break that the line held back for a played sensor's character
(twenty-second outside round, docs/kit.md: davemortek/stm32-sdi-12 through the C kit).

The library began its break for ``0IM!`` at the end of the 50th character of the sensor's
``0XHELP!`` text, where the next character began. The tool gave that character the line and
told the harness ``char``; the kit planned the whole break again from its end, so the break
ended off the firmware's 1 ms tick and ``HAL_Delay(7)`` from there marked 7.67 ms, where on a
board (the break going over the character, ending on a tick) it marks 8.00 ms: a false
R-7.0-06 FAIL. The link knows the break was held back and marks it (``HELD_BACK``); a marking
after it that would FAIL is INCONCLUSIVE (where the recorder's own timing would have put its
command after its break on a wire is not known), one that passes still PASSes (holding a break
back only ever moves its end later, so the recorder's command comes no nearer to it on a wire).
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace

from conformance.conduct import run_into
from conformance.harness.protocol import Plan, PlanKind
from conformance.judges.recorder.breaks import judge_breaks
from conformance.protocol.timing import CHAR_TIME
from conformance.recorder.harness_driver import HarnessRecorder
from conformance.recorder.job_time import JobBudget
from conformance.transcript import HELD_BACK, TOOL, Event, EventKind, Transcript, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.segments import read_view
from tests.support.harness_script import PRELUDE

#: A recorder harness whose timing runs from the break it asked for, as a firmware's does that
#: counts its marking from where it began its break (an absolute deadline; the kit's HAL glue
#: on a 1 ms tick is the same class): each command after a break of 13 ms and 8.4 ms of
#: marking from the break it asked for, each command twice. After the first character of a
#: reply it begins the next command's break 1 ms after that character's end, inside the
#: reply's next character; hearing a character instead of its break, it asks for the whole
#: break again from that character's end (the C kit's ``sdi12_kit_break``). ``ASKED`` in the
#: environment: ask for the break after the reply has ended instead (nothing holds it back).
_ASKS_FROM_ITS_OWN_BREAK = (
    PRELUDE
    + r"""
import os

late = bool(os.environ.get("ASKED"))
cmds, i, tries, sent, phase, asked_end, at = [], 0, 0, 0, "", 0, 0

def brk(now):
    global phase, asked_end
    phase, asked_end = "brk", now + 13000
    say(f"brk {now} {now + 13000}")

def tx():
    say(f"tx {at} {wire(cmds[i][sent]):02x}")

def next_command(now):
    global i, tries, phase
    tries += 1
    if tries == 2:  # each command twice
        i, tries = i + 1, 0
    if i >= len(cmds):
        phase = "done"
        say("done")
    elif late:
        phase = "heard"
        say(f"wait {now + 200000}")
    else:
        brk(now)

for line in sys.stdin:
    word, *f = line.split()
    if word == "bye":
        break
    if word == "hello":
        say("hello 1 asks-from-its-own-break")
    elif word == "job":
        cmds, i, tries = f[2:], 0, 0
        brk(int(f[0]))
    elif phase == "brk" and word == "char":  # held back: the whole break again from now
        say(f"brk {f[1]} {int(f[1]) + 13000}")
    elif phase == "brk":  # its break
        phase, sent, at = "tx", 0, asked_end + 8400
        tx()
    elif phase == "tx" and word == "sent":
        sent, at = sent + 1, int(f[1])
        if sent < len(cmds[i]):
            tx()
        else:
            phase = "listen"
            say(f"wait {at + 1000000}")
    elif phase == "tx":  # a character heard: the same character, as soon as it may
        tx()
    elif phase == "listen" and word == "char":
        phase = "heard"
        next_command(int(f[1]) + 1000)
    elif phase == "listen":  # time: no reply
        next_command(int(f[0]))
    elif phase == "heard" and late and word == "time":  # the reply is long over
        brk(int(f[0]))
    elif phase == "heard" and late:
        say(f"wait {int(f[1]) + 200000}")
    else:
        say("idle")
"""
)


def _run(tmp_path, monkeypatch, asked_late: bool = False) -> tuple[dict, list[dict]]:
    harness = tmp_path / "asks.py"
    harness.write_text(_ASKS_FROM_ITS_OWN_BREAK)
    if asked_late:
        monkeypatch.setenv("ASKED", "1")
    out = tmp_path / "run"
    found = run_into(
        out, f"exec:{sys.executable} {harness}", "recorder", keyword="test_breaks", version="1.3"
    )
    lines = (out / "transcript.jsonl").read_text().splitlines()
    return found, [json.loads(line) for line in lines]


def _rule(found: dict, rid: str) -> dict:
    return next(r for r in found["requirements"] if r["id"] == rid)


def test_a_break_the_line_held_back_is_marked_in_the_transcript_r_7_0_06(tmp_path, monkeypatch):
    _, events = _run(tmp_path, monkeypatch)
    breaks = [e for e in events if e["kind"] == "break" and e["origin"] == TOOL]
    held = [e for e in breaks if e["text"] == HELD_BACK]
    assert held, breaks[:5]
    assert len(held) < len(breaks)  # each job's first break is where it was asked for


def test_marking_after_a_held_back_break_is_no_false_fail_r_7_0_06(tmp_path, monkeypatch):
    """FAILed 'marking after the break: 0.00 ms' on the tree before: the command went where
    the recorder's timing from the break it asked for put it, inside the break the line had
    moved later."""
    found, _ = _run(tmp_path, monkeypatch)
    row = _rule(found, "R-7.0-06")
    assert row["verdict"] == "INCONCLUSIVE", row["findings"]
    assert "held back" in row["findings"][0]["detail"], row["findings"]
    assert _rule(found, "R-7.0-02")["verdict"] == "PASS"  # its 13 ms breaks, as asked


def test_the_same_recorder_breaking_after_the_reply_passes_r_7_0_06(tmp_path, monkeypatch):
    """Asked for after the reply, nothing holds the break back: 8.4 ms of marking, PASS (the
    harness and the judge can tell a break apart from one the line moved)."""
    found, events = _run(tmp_path, monkeypatch, asked_late=True)
    assert not [e for e in events if e["kind"] == "break" and e["text"] == HELD_BACK]
    row = _rule(found, "R-7.0-06")
    assert row["verdict"] == "PASS", row["findings"]


def _wire(held: bool, marking_ms: float) -> list[Event]:
    brk = Event(EventKind.BREAK, TOOL, 0.0, 0.013, text=HELD_BACK if held else "")
    t = 0.013 + marking_ms / 1e3
    chars = []
    for c in "0!":
        chars.append(Event(EventKind.CHAR, TOOL, t, t + CHAR_TIME, to_wire_7e1(ord(c))))
        t += CHAR_TIME
    return [brk, *chars]


def _r_7_0_06(events: list[Event]):
    return next(f for f in judge_breaks(read_view(events), 0.0) if f.requirement == "R-7.0-06")


def test_a_short_marking_after_a_held_back_break_is_inconclusive_r_7_0_06():
    assert _r_7_0_06(_wire(False, 5.0)).verdict is Verdict.FAIL
    held = _r_7_0_06(_wire(True, 5.0))
    assert held.verdict is Verdict.INCONCLUSIVE
    assert held.measured_ms == 5.0


def test_a_marking_that_holds_after_a_held_back_break_still_passes_r_7_0_06():
    assert _r_7_0_06(_wire(True, 9.0)).verdict is Verdict.PASS


def test_a_short_marking_after_a_break_where_asked_still_fails_beside_a_held_one_r_7_0_06():
    events = _wire(True, 5.0)
    later = [replace(e, start=e.start + 1.0, end=e.end + 1.0, text="") for e in _wire(False, 4.0)]
    assert _r_7_0_06(events + later).verdict is Verdict.FAIL


class _Channel:
    """A harness that asks for one break at 1.000000 s, then is done."""

    features: frozenset[str] = frozenset()

    def __init__(self) -> None:
        self.told: list[str] = []

    def plan(self, message: str, role, now: float, since: float | None = None) -> Plan:
        self.told.append(message)
        return Plan(PlanKind.DONE)


class _LineTakenFirst:
    """The sim bus as the twenty-second round met it: a played sensor's character planned for
    the instant the break was asked for (to the float's last bit) goes first, whole, and the
    break follows it (:meth:`SimBus.tool_break` after committing what began before now)."""

    def __init__(self, late: float) -> None:
        self.transcript = Transcript()
        self.late = late
        self.clock = 1.0

    def now(self) -> float:
        return self.clock

    def receive(self, deadline, until=None, idle=None):
        self.clock = max(self.clock, deadline)
        return []

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        start = self.clock
        if self.late:
            self.transcript.add(Event(EventKind.CHAR, "dut", start, start + self.late, 0x0A))
            start += self.late
        self.clock = start + duration
        return self.transcript.add(Event(EventKind.BREAK, TOOL, start, self.clock))


def _break_as_put(late: float) -> Event:
    link = _LineTakenFirst(late)
    HarnessRecorder("exec:none")._drive(
        _Channel(), Plan(PlanKind.BRK, start=1_000_000, end=1_013_000), link, JobBudget(60, "")
    )
    return next(e for e in link.transcript if e.kind is EventKind.BREAK)


def test_a_break_the_line_began_after_a_sensors_character_is_marked_r_7_0_06():
    """The davemortek run's path: the harness never heard the character before its break (the
    line told it the break first), so only the break's start, a frame after the one asked
    for, says the line held it back. Unmarked on the tree before."""
    assert _break_as_put(CHAR_TIME).text == HELD_BACK
    assert _break_as_put(CHAR_TIME).start == 1.0 + CHAR_TIME


def test_a_break_where_it_was_asked_is_not_marked_r_7_0_06():
    assert _break_as_put(0.0).text == ""
    assert _break_as_put(1.5e-6).text == ""  # within the 2 us a plan for "now" may be off
