"""What the recorder under test is asked to do in one scenario, and what it reports back.

A request is plain data so that the same scenario can be handed to an in-process recorder (a
Python callable), to an external logger through a trigger command (environment variables), or
to an operator (a prompt). The recorder's answer (:class:`RecorderOutput`) is optional
evidence: what it logged and relayed. The wire transcript is what the judges rely on.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum


class Task(StrEnum):
    #: Take each measurement in turn (break, command, SR or ttt, D0..Dn) and log the values.
    MEASURE = "measure"
    #: Start every measurement first (concurrent commands), then collect each one's data.
    CONCURRENT = "concurrent"
    #: Issue each command once (with the usual retries) and log the reply.
    COMMAND = "command"
    #: Transparent mode: pass each host command through unchanged and relay the reply.
    TRANSPARENT = "transparent"


@dataclass(frozen=True)
class Request:
    """``task`` over ``commands`` (wire text with address and ``!``, e.g. ``0M!``)."""

    task: Task
    commands: tuple[str, ...]

    def sentence(self) -> str:
        """One line an operator can act on."""
        listed = ", ".join(self.commands)
        match self.task:
            case Task.MEASURE:
                return f"take these measurements one after the other and log the data: {listed}"
            case Task.CONCURRENT:
                return (
                    f"start these concurrent measurements together, then collect and log each "
                    f"one's data: {listed}"
                )
            case Task.COMMAND:
                return f"send these commands and log the replies: {listed}"
            case Task.TRANSPARENT:
                return f"in transparent mode, send these commands from the host: {listed}"
        raise ValueError(self.task)

    def environment(self, scenario: str, timeout: float) -> dict[str, str]:
        """What a trigger command receives (documented in the README)."""
        return {
            "SDI12_SCENARIO": scenario,
            "SDI12_TASK": str(self.task),
            "SDI12_COMMANDS": " ".join(self.commands),
            "SDI12_REQUEST": self.sentence(),
            "SDI12_TIMEOUT_S": f"{timeout:g}",
        }


@dataclass
class RecorderOutput:
    """What the recorder says it did: values logged per measurement command, replies relayed
    per transparent command, and free text (a trigger's stdout, an operator's note)."""

    logged: dict[str, list[str]] = field(default_factory=dict)
    relayed: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    #: Where ``logged`` came from ("3 log lines from the harness", "SDI12_LOG_FILE, CSV"),
    #: set when the recorder reported it even if it logged nothing; an in-process program's
    #: non-empty ``logged`` counts as reported without it.
    log_source: str | None = None
    #: Why the recorder's report of what it logged could not be read (names the line).
    log_problem: str | None = None
    #: The recorder said it cannot do this job (a harness's ``cannot``, a trigger's exit
    #: code 3): its own words ("" when it gave none); None when it said no such thing.
    cannot: str | None = None
    #: An ``exec:`` harness's own log: the tail of what it wrote to stderr in this job.
    stderr: str | None = None

    def reported_logged(self) -> dict[str, list[str]] | None:
        """``logged`` if the recorder reported what it logged (even nothing), else None."""
        return dict(self.logged) if self.logged or self.log_source is not None else None
