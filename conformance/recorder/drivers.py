"""How the recorder under test is made to act on a scenario's request.

Three ways, one interface (``act(scenario, request, link) -> RecorderOutput``):

- :class:`InProcess`: a Python callable ``(request, link) -> RecorderOutput`` runs on the
  tool's link. This is how the golden recorder (and any recorder logic written in Python) is
  judged on the virtual-time bus, where nothing outside the process can reach the line.
- :class:`Trigger`: a shell command run once per scenario, with the request in environment
  variables (``SDI12_SCENARIO``, ``SDI12_TASK``, ``SDI12_COMMANDS``, ``SDI12_REQUEST``,
  ``SDI12_TIMEOUT_S``), for a logger driven from CI. What the logger logged is read from
  the file it writes at ``SDI12_LOG_FILE`` (:mod:`.logfile`); its stdout is kept as a note.
- :class:`Interactive`: a prompt telling the operator what to make the logger do, answered by
  Enter (or an empty line) or left to time out.

Trigger and Interactive need the played sensors served in real time on a real port while the
logger acts; the session refuses them where that is impossible (the simulated bus).
"""

from __future__ import annotations

import os
import select
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, TextIO

from ..links.base import Link
from ..recorder_jobs import RecorderOutput, Request
from .errors import RecorderDriverError, RecorderSetupError
from .job_time import JobBudget, JobLink, JobTimeout
from .logfile import LOG_FILE_VARIABLE, LogFileError, read_log_file

__all__ = ["RecorderDriverError", "RecorderSetupError", "JobTimeout"]  # re-exported

#: The exit code by which a trigger says "this logger cannot do this job" (README).
CANNOT_EXIT = 3
#: The word an operator types (then why) to say the same at the interactive prompt.
CANNOT_WORD = "cannot"
#: Longest trigger output kept as evidence (the DUT's words are untrusted and unbounded).
MAX_OUTPUT = 4000
MAX_STDERR = 600  # a failing trigger's own words, shown to the user as they are
#: Wall time a trigger gets beyond its job's budget to start the logger and reach the line.
START = 30.0


class Driver(Protocol):
    kind: str
    needs_real_time: bool

    def act(
        self, scenario: str, request: Request, link: Link, budget: JobBudget | None = None
    ) -> RecorderOutput:
        """Make the recorder do ``request`` on ``link``; ``budget``: the bus time the job may
        take (:mod:`.job_time`), past which the driver raises :class:`JobTimeout`."""
        ...


@dataclass
class InProcess:
    """A recorder program in this process (the golden recorder by default)."""

    program: Callable[[Request, Link], RecorderOutput]
    kind: str = "in-process"
    needs_real_time: bool = False

    def act(
        self, scenario: str, request: Request, link: Link, budget: JobBudget | None = None
    ) -> RecorderOutput:
        if budget is None:
            return self.program(request, link)
        return self.program(request, JobLink(link, budget))  # type: ignore[arg-type]


@dataclass
class Trigger:
    """``command`` run through the shell per scenario, bounded by ``timeout`` seconds."""

    command: str
    timeout: float = 120.0
    kind: str = "trigger"
    needs_real_time: bool = True
    #: Set by the session: where the recorder connects (``SDI12_PORT``, an rfc2217:// URL).
    environment: dict[str, str] = field(default_factory=dict)

    def act(
        self, scenario: str, request: Request, link: Link, budget: JobBudget | None = None
    ) -> RecorderOutput:
        with tempfile.TemporaryDirectory(prefix="sdi12-log-") as folder:
            log_file = Path(folder) / f"{scenario}.log"
            out = self._run(scenario, request, log_file, budget)
            if out.cannot is not None:
                return out
            try:
                out.logged = read_log_file(log_file) or {}
                if log_file.exists():
                    out.log_source = f"{LOG_FILE_VARIABLE} ({len(out.logged)} command(s))"
            except LogFileError as exc:
                out.log_problem = f"{LOG_FILE_VARIABLE} {exc}"
        return out

    def _run(
        self, scenario: str, request: Request, log_file: Path, budget: JobBudget | None
    ) -> RecorderOutput:
        # the job's budget when it is longer than --trigger's own timeout, plus the time a
        # trigger may need to start the logger and reach the line
        timeout = self.timeout if budget is None else max(self.timeout, budget.seconds + START)
        env = {
            **os.environ,
            **self.environment,
            **request.environment(scenario, timeout if budget is None else budget.seconds),
            LOG_FILE_VARIABLE: str(log_file),
        }
        try:
            done = subprocess.run(
                self.command,
                shell=True,
                env=env,
                capture_output=True,
                text=True,
                timeout=timeout,
                check=False,
            )
        except subprocess.TimeoutExpired as exc:
            if budget is not None:
                raise JobTimeout(timeout, f"{budget.reason}, and {START:g} s to start") from exc
            raise RecorderDriverError(
                f"trigger did not finish within {self.timeout:g} s: {self.command}"
            ) from exc
        if done.returncode == CANNOT_EXIT:  # the logger cannot do this job: its words
            words = (done.stderr.strip() or done.stdout.strip())[:MAX_STDERR]
            return RecorderOutput(cannot=words)
        if done.returncode != 0:
            said = done.stderr.strip()[:MAX_STDERR] or "(nothing on stderr)"
            raise RecorderDriverError(
                f"trigger {self.command!r} exited with {done.returncode}: {said}"
            )
        out = RecorderOutput()
        text = done.stdout[:MAX_OUTPUT].strip()
        if text:
            out.notes.append(text)
        return out


@dataclass
class Interactive:
    """Asks an operator to make the logger act, and waits for Enter up to ``timeout`` s."""

    timeout: float = 300.0
    prompt_out: TextIO = field(default_factory=lambda: sys.stdout)
    answer_in: TextIO = field(default_factory=lambda: sys.stdin)
    kind: str = "interactive"
    needs_real_time: bool = True
    #: Set by the session: where the recorder connects (``SDI12_PORT``, an rfc2217:// URL).
    environment: dict[str, str] = field(default_factory=dict)

    def prompt(self, scenario: str, request: Request) -> str:
        where = self.environment.get("SDI12_PORT")
        return (
            f"\n[recorder scenario {scenario}] Make the data recorder {request.sentence()}"
            + (f" (sensors served at {where})" if where else "")
            + ".\n"
            f"Press Enter when it has finished (you may type a note first), or type "
            f"'{CANNOT_WORD} WHY' if this logger cannot do it; "
            f"{self.timeout:g} s until this scenario is abandoned: "
        )

    def act(
        self, scenario: str, request: Request, link: Link, budget: JobBudget | None = None
    ) -> RecorderOutput:
        self.prompt_out.write(self.prompt(scenario, request))
        self.prompt_out.flush()
        ready, _, _ = select.select([self.answer_in], [], [], self.timeout)
        if not ready:
            raise RecorderDriverError(f"no answer from the operator within {self.timeout:g} s")
        note = self.answer_in.readline().strip()
        word, _, why = note.partition(" ")
        if word.lower() == CANNOT_WORD:  # as a harness's `cannot` or a trigger's exit 3
            return RecorderOutput(cannot=why.strip()[:MAX_STDERR])
        out = RecorderOutput()
        if note:
            out.notes.append(note[:MAX_OUTPUT])
        return out
