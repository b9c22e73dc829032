"""How long the recorder under test may take over one scenario's job, and the cut at that time.

A logger that loops forever (waiting for a service request that never comes, spinning on a
ttt of 000) must not hang the run, nor turn every rule into INCONCLUSIVE: its job is cut at a
stated budget of bus time, and what it sent until then is judged. The budget is what a
conforming recorder could need, generously: a fixed allowance, plus for each command asked an
allowance for its retries and data commands and the longest ttt the played sensor at that
address announces. ``--job-timeout S`` replaces it for every scenario (a logger with its own
slow schedule). The budget is stated in the scenario's note, in ``SDI12_TIMEOUT_S`` and in the
findings of a job that was cut.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..links.base import Link, StopCondition
from ..recorder_jobs import Request
from ..transcript import Event
from .errors import RecorderDriverError

#: Bus time every job may take whatever it asks (waking sensors, the logger's own start-up).
BASE_ALLOWANCE = 30.0
#: Bus time per command asked on top of its ttt: three break + command + retries sequences,
#: and data commands up to D9 (or D14 and long binary packets after HA/HB) with their retries.
PER_COMMAND = 10.0
#: The kinds of command whose reply announces a ttt the recorder waits out.
_MEASURING = frozenset("MCVH")


class JobTimeout(RecorderDriverError):
    """The recorder did not finish its job within the scenario's budget of bus time."""

    #: a harness's stderr tail up to the cut (its own log explains a loop)
    stderr: str | None = None

    def __init__(self, budget: float, reason: str) -> None:
        super().__init__(
            f"the recorder did not finish its job within its {budget:g} s of bus time "
            f"({reason}); what it sent until then is judged"
        )
        self.budget = budget
        self.reason = reason
        #: the line time of the cut, set by whoever holds the line's clock (the scenario runner)
        self.at: float | None = None


@dataclass(frozen=True)
class JobBudget:
    """The bus time one job may take, and how it was arrived at (shown to the user)."""

    seconds: float
    reason: str

    def note(self) -> str:
        return f"job timeout {self.seconds:g} s of bus time ({self.reason})"


def job_budget(request: Request, played: Sequence[object], override: float | None) -> JobBudget:
    """The budget of ``request`` on a bus with the ``played`` sensors; ``override`` (the
    ``--job-timeout`` option) replaces it."""
    if override is not None:
        return JobBudget(override, "--job-timeout")
    ttt = 0
    for command in request.commands:
        kind = command[1:2]
        if kind in _MEASURING:
            ttt += _longest_ttt(played, command[:1])
    count = len(request.commands)
    seconds = BASE_ALLOWANCE + PER_COMMAND * count + ttt
    reason = f"{BASE_ALLOWANCE:g} s, {PER_COMMAND:g} s for each of its {count} command(s)" + (
        f" and {ttt} s of the ttt the played sensors announce" if ttt else ""
    )
    return JobBudget(seconds, reason)


def _longest_ttt(played: Sequence[object], address: str) -> int:
    for device in played:
        if getattr(device, "address", None) == address:
            specs = device.profile.measurements.values()  # type: ignore[attr-defined]
            return max((spec.ttt for spec in specs), default=0)
    return 0


class JobLink:
    """The recorder's end of the line for one job: the link itself until the budget's end,
    where any wait, receive or transmission past it raises :class:`JobTimeout` (the in-process
    recorder's waits are cut there, so a program that waits forever ends)."""

    def __init__(self, link: Link, budget: JobBudget) -> None:
        self._link = link
        self.budget = budget
        self.deadline = link.now() + budget.seconds

    def __getattr__(self, name: str) -> object:
        return getattr(self._link, name)

    def _check(self) -> None:
        if self._link.now() >= self.deadline:
            raise JobTimeout(self.budget.seconds, self.budget.reason)

    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        self._check()
        got = self._link.receive(min(deadline, self.deadline), until, idle)
        if not got and deadline > self.deadline:
            self._check()
        return got

    def wait_until(self, time: float) -> None:
        self._check()
        self._link.wait_until(min(time, self.deadline))
        if time > self.deadline:
            self._check()

    def wait(self, duration: float) -> None:
        self.wait_until(self._link.now() + duration)

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        self._check()
        return self._link.write(wire, gap)

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        self._check()
        return self._link.send_break(duration, exact=exact)
