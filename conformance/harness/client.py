"""The harness side of the protocol, for harnesses written in Python.

:class:`ClientLink` is a :class:`~conformance.links.base.Link` whose bus is the tool at the
other end of stdin/stdout: ``write`` answers ``tx`` and waits for ``sent``, ``send_break``
answers ``brk``, ``receive``/``wait_until`` answer ``wait`` and collect the characters heard
meanwhile. Any recorder program written against a :class:`Link` (the golden recorder, or your
own) thereby runs as a recorder harness: :func:`serve_recorder` does the job it is given and
answers ``done`` after ``log`` lines of what it logged. The protocol itself is specified in
``docs/harness-protocol.md``; harnesses in other languages implement it directly.
"""

from __future__ import annotations

import sys
from collections import deque
from collections.abc import Callable
from typing import TextIO

from ..links.base import Link, LinkError, LinkInfo, StopCondition
from ..recorder_jobs import RecorderOutput, Request, Task
from ..transcript import DUT, TOOL, Event, EventKind, Transcript
from .protocol import LOG, MAX_LINE, VERSION, seconds, us


class ClientLink(Link):
    """A link from inside a harness: the tool owns the clock, this side only plans."""

    def __init__(self, inp: TextIO, out: TextIO) -> None:
        self.inp, self.out = inp, out
        self.info = LinkInfo(kind="harness", virtual_time=True)
        self.transcript = Transcript()
        self.clock = 0.0
        self.heard: deque[Event] = deque()

    def now(self) -> float:
        return self.clock

    def reply(self, line: str) -> list[str]:
        """Answer the tool's last message and read its next one (split into fields)."""
        self.out.write(line + "\n")
        self.out.flush()
        message = self.inp.readline()
        if not message:
            raise LinkError("the tool closed the harness's input")
        fields = message.split()
        if fields[0] == "bye":
            raise LinkError("the tool ended the run")
        if fields[0] in ("char", "sent", "break"):
            start, end = seconds(int(fields[1])), seconds(int(fields[2]))
            self.clock = end
            if fields[0] == "char":
                event = Event(EventKind.CHAR, DUT, start, end, wire=int(fields[3], 16))
                self.heard.append(self.transcript.add(event))
        elif fields[0] == "time":
            self.clock = seconds(int(fields[1]))
        return fields

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        start = self.clock
        while (fields := self.reply(f"brk {us(start)} {us(start + duration)}"))[0] != "break":
            start = self.clock
        event = Event(EventKind.BREAK, TOOL, seconds(int(fields[1])), seconds(int(fields[2])))
        return self.transcript.add(event)

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        events: list[Event] = []
        start = self.clock
        for byte in wire:
            while (fields := self.reply(f"tx {us(start)} {byte:02x}"))[0] != "sent":
                start = max(start, self.clock)
            begin, end = seconds(int(fields[1])), seconds(int(fields[2]))
            events.append(self.transcript.add(Event(EventKind.CHAR, TOOL, begin, end, wire=byte)))
            start = end + gap
        return events

    def wait_until(self, time: float) -> None:
        while us(time) > us(self.clock):
            self.reply(f"wait {us(time)}")
        self.clock = max(self.clock, time)  # within the protocol's 1 us resolution

    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        got: list[Event] = []
        while True:
            while self.heard:
                got.append(self.heard.popleft())
                if until is not None and until(got):
                    return got
            limit = deadline
            if idle is not None and got:
                limit = min(deadline, got[-1].end + idle)
            if us(limit) <= us(self.clock):
                self.clock = max(self.clock, limit)  # as on the sim bus: the deadline passed
                return got
            self.reply(f"wait {us(limit)}")


def log_lines(command: str, values: list[str]) -> list[str]:
    """``log`` lines reporting ``values`` logged for ``command``, each within the protocol's
    line length (a long measurement takes several lines; the tool appends them)."""
    lines, line = [], f"{LOG} {command}"
    for value in values:
        if len(line) + 1 + len(value) > MAX_LINE and line != f"{LOG} {command}":
            lines.append(line)
            line = f"{LOG} {command}"
        line += f" {value}"
    return [*lines, line]


def serve_recorder(
    program: Callable[[Request, Link], RecorderOutput],
    inp: TextIO = sys.stdin,
    out: TextIO = sys.stdout,
    name: str = "python-recorder",
) -> int:
    """Run one recorder job over stdin/stdout: hello, job, the program's work, ``log`` lines
    of what it logged, done, bye."""
    hello = inp.readline().split()
    if hello[:2] != ["hello", str(VERSION)]:
        print(f"expected 'hello {VERSION} recorder', got {hello}", file=sys.stderr)
        return 2
    out.write(f"hello {VERSION} {name}\n")
    out.flush()
    job = inp.readline().split()
    if job[:1] == ["bye"] or not job:  # the tool only checked that the harness starts
        return 0
    if job[0] != "job" or len(job) < 3:
        print(f"expected 'job TIME TASK COMMAND...', got {job}", file=sys.stderr)
        return 2
    link = ClientLink(inp, out)
    link.clock = seconds(int(job[1]))
    try:
        output = program(Request(Task(job[2]), tuple(job[3:])), link)
    except LinkError as exc:  # the tool ended the conversation (bye, or closed our input)
        print(f"job ended by the tool: {exc}", file=sys.stderr)
        return 0
    for command, values in output.logged.items():
        for line in log_lines(command, values):
            out.write(line + "\n")
    if output.cannot is not None:  # the program says its logger cannot do this job
        out.write(" ".join(("cannot", *output.cannot.split())) + "\n")
    else:
        out.write("done\n")
    out.flush()
    inp.readline()  # bye
    return 0
