"""The recorder under test as the recorder-role cases see it: the scenario runner.

One bus for the whole run: before each scenario the played sensors are put on it, the
recorder is made to act on the scenario's request, and the slice of the transcript it left is
kept with what the recorder said it logged. Each scenario runs at most once per run; every case
that needs it judges the same slice.

On ``--port sim`` the bus is the virtual-time :class:`SimBus`, the recorder runs in this
process on the tool's :class:`SimLink` (the golden recorder unless ``recorder=`` names another
callable), and its side of the wire has origin ``tool``. On ``--port rfc2217-serve://HOST:PORT``
the tool serves the played sensors in real time (:mod:`conformance.recorder.served_line`) and the
recorder connects to them over RFC 2217: the in-process one through a real link opened per
scenario, an external one (``--trigger``) told where in ``SDI12_PORT``. The transcript is then
the served line's, as the sensors hear it, in the same form.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from ..declaration import Declaration
from ..dut import Session
from ..harness.channel import STDERR_TAIL
from ..links.base import LinkError
from ..links.host_stall import Stall, stalls
from ..links.registry import PortOptions
from ..protocol.version import V14, format_version, is_v14
from ..recorder_jobs import RecorderOutput, Request
from ..results import CaseRecord
from ..sim.bus import SimBus
from ..sim.line_monitor import LineMonitor
from ..transcript import TOOL, Event, EventKind
from ..view.segments import TranscriptView, merge_views, read_view
from .capability import Absence, Capabilities, cannot_finding, sent_tokens
from .drivers import (
    Driver,
    Interactive,
    RecorderDriverError,
    RecorderSetupError,
    Trigger,
)
from .harness_driver import HarnessRecorder
from .job_time import JobBudget, JobTimeout, job_budget
from .openers import open_recorder_line
from .played import build_sensors
from .replay_driver import output_note
from .scenarios import SCENARIOS, Scenario
from .served_line import ServedLine

#: Marking left after a recorder finished, so late sensor output is on record and the next
#: scenario starts on a quiet line with every sensor in standby.
SETTLE = 1.0


@dataclass
class ScenarioRun:
    """What one scenario left: its transcript slice and the recorder's own account."""

    scenario: Scenario
    events: list[Event]
    output: RecorderOutput
    error: str | None = None
    played: tuple[object, ...] = ()
    #: what the recorder was asked: the scenario's request less the commands its
    #: declaration rules out where the standard lets it (recorder.capability)
    request: Request | None = None
    absences: tuple[Absence, ...] = ()
    #: the job ran out of its budget of bus time (``error`` says so too): what the recorder
    #: sent until then is all it sent, so rules over every transmission judge it in full
    timed_out: JobTimeout | None = None
    budget: JobBudget | None = None
    #: line time at which the recorder's job ended (its done, cannot or failure; a cut job's
    #: cut): what a sensor began to send after it, the recorder did not hear in the job
    ended_at: float | None = None

    @property
    def cut_at(self) -> float | None:
        """Line time at which the tool cut the job (``timed_out``): the recorder was still
        in it, so what it had not sent by then it may yet have sent."""
        return self.timed_out.at if self.timed_out is not None else None

    @property
    def asked(self) -> tuple[str, ...]:
        return (self.request or self.scenario.request).commands

    def expected_values(self, address: str, code: str) -> tuple[str, ...]:
        """The values the played sensor at ``address`` holds for measurement ``code``."""
        for device in self.played:
            if getattr(device, "address", None) == address:
                spec = device.profile.measurements.get(code)  # type: ignore[attr-defined]
                return spec.values if spec is not None else ()
        return ()


class RecorderSession(Session):
    """Runs scenarios against the recorder under test and keeps their records."""

    def __init__(
        self,
        port: str,
        *,
        version: str = V14,
        driver: Driver | None = None,
        timing_uncertainty: float | None = None,
        declaration: Declaration | None = None,
        job_timeout: float | None = None,
    ) -> None:
        self.job_timeout = job_timeout  # --job-timeout: one budget for every job
        options = PortOptions(timing_uncertainty=timing_uncertainty)
        opened = open_recorder_line(port, options, driver)
        self.driver = opened.driver
        self.faults = opened.faults
        self.served = opened.served
        self.link = opened.link  # what the reports read: the sim bus's tool end, or the line
        self._bus = opened.bus
        self.version = version
        self.capabilities = Capabilities(declaration, version)
        self.recorder_origins = frozenset({TOOL})
        self.runs: dict[str, ScenarioRun] = {}
        self.address = None  # a recorder has no address of its own
        self.address_notes: list[str] = []  # the recorder role changes no DUT address
        self.assumptions = [
            f"recorder claims SDI-12 v{format_version(version)}",
            f"recorder driven {self.driver.kind}" + _with_faults(self.faults),
        ]
        if self.served is not None:
            self.assumptions.append(
                f"played sensors served in real time at {self.served.url}; stamps taken on the "
                f"served line, \u00b1{self.uncertainty * 1e3:g} ms"
            )
        self.assumptions += self.capabilities.assumptions()

    @property
    def is_v14(self) -> bool:
        return is_v14(self.version)

    @property
    def uncertainty(self) -> float:
        """The stamps' uncertainty (s): the line's figure, widened by the user's."""
        return self.link.timing_uncertainty()

    def link_facts(self) -> dict[str, Any]:
        """A recorder harness's stderr, one tail per scenario (nothing without a harness)."""
        tail = self.harness_stderr()
        return {} if tail is None else {"harness_stderr": tail}

    def worst_lateness(self) -> float:
        """How far the served line fell behind its schedule (s; 0 on the sim bus)."""
        return self.served.line.worst_lateness if self.served is not None else 0.0

    def unexplained_lateness(self) -> float:
        """How far the served line fell behind its schedule for frames due outside every
        stall of this process it noted (s; 0 on the sim bus)."""
        return self.served.line.unexplained_lateness if self.served is not None else 0.0

    def recorder_in_process(self) -> bool:
        """Whether the recorder acts through this process (not one that connects to the
        served line itself): the host's stalls of this process hold it up too (truth34)."""
        return not self.driver.needs_real_time

    def noted_stalls(self) -> list[Stall]:
        """The stalls of this process the served line noted (truth32; every frame it sent
        late since truth34), in its transcript's order; none on the sim bus."""
        return stalls(self.served.transcript.events) if self.served is not None else []

    @property
    def bus(self) -> SimBus:
        """The virtual-time bus the played sensors go on (not on a served line)."""
        assert self._bus is not None, "played sensors are served in real time"
        return self._bus

    def is_recorder(self, event: Event) -> bool:
        return event.origin in self.recorder_origins

    def applies(self, name: str) -> bool:
        """Whether the scenario binds this recorder (v1.4-only ones need a v1.4 claim)."""
        return self.is_v14 or not SCENARIOS[name].v14

    def applicable(self) -> list[str]:
        return [name for name in SCENARIOS if self.applies(name)]

    def view(self, *names: str) -> TranscriptView:
        """The scenarios' transcripts read as the recorder's transmissions, one part each."""
        view = merge_views(
            [read_view(self.run(n).events, self.is_recorder, part=i) for i, n in enumerate(names)]
        )
        view.cut_parts = {
            i: cut for i, n in enumerate(names) if (cut := self.run(n).cut_at) is not None
        }
        view.ended_parts = {
            i: end
            for i, n in enumerate(names)
            if (end := self.run(n).ended_at) is not None and i not in view.cut_parts
        }
        return view

    def run(self, name: str) -> ScenarioRun:
        """The scenario's record, running it the first time it is asked for."""
        if name not in self.runs:
            self.runs[name] = self._run(SCENARIOS[name])
        return self.runs[name]

    def apply_declaration(self, record: CaseRecord) -> None:
        """A case's findings read with what the recorder said it cannot do (a harness's
        ``cannot``, a trigger's exit code 3) and with its declaration (recorder.capability)."""
        used = [
            title.removeprefix("scenario ").split(":", 1)[0]
            for title, _ in record.evidence
            if title.startswith("scenario ")
        ]
        for name in dict.fromkeys(used):
            run = self.runs.get(name)
            if run is None or run.output.cannot is None:
                continue
            for rid in record.requirements:
                said = run.output.cannot
                found = cannot_finding(rid, name, said, run.asked, record.findings, self.version)
                if found is not None:
                    record.findings.append(found)
        sent: set[str] = set()
        for run in self.runs.values():
            sent |= sent_tokens(run.events, self.is_recorder)
        self.capabilities.apply(record.findings, sent)

    def run_scenario(self, scenario: Scenario) -> ScenarioRun:
        """Run a scenario that is not one of :data:`SCENARIOS` (a tolerance sweep's step),
        every time it is asked for: nothing is kept, so no case judges it."""
        return self._run(scenario)

    def _run(self, scenario: Scenario) -> ScenarioRun:
        if self.served is not None:
            return self._run_served(scenario, self.served)
        played = build_sensors(scenario.sensors)
        self.bus.devices[:] = [LineMonitor(), *played]
        self.bus.rx.clear()
        transcript = self.link.transcript
        first = len(transcript)
        transcript.note(self.link.now(), f"scenario {scenario.name}: {scenario.describe()}")
        request, absences = self.capabilities.trim(scenario.request)
        for absence in absences:
            transcript.note(self.link.now(), self._absence_note(absence))
        budget = job_budget(request, played, self.job_timeout)
        transcript.note(self.link.now(), budget.note())
        error, cut = None, None
        try:
            output = self.driver.act(scenario.name, request, self.link, budget)
        except RecorderDriverError as exc:
            output, error, cut = _failed(exc)
        ended = self.link.now()
        if cut is not None:
            cut.at = ended
        transcript.note(ended, output_note(scenario.name, output, error, cut))
        self.bus.advance(self.link.now() + SETTLE)
        self.bus.rx.clear()
        events = transcript.since(first)
        self._check_setup(scenario, events, error, cut)
        return ScenarioRun(
            scenario,
            events,
            output,
            error,
            tuple(played),
            request,
            tuple(absences),
            cut,
            budget,
            ended,
        )

    @staticmethod
    def _absence_note(absence: Absence) -> str:
        if absence.mandatory is None:
            return f"not asked: {absence.text()} (optional)"
        return f"asked all the same: {absence.text()} ({absence.mandatory} requires it)"

    def _check_setup(
        self,
        scenario: Scenario,
        events: list[Event],
        error: str | None,
        cut: JobTimeout | None = None,
    ) -> None:
        """A driver that failed while the recorder stayed silent is a setup error: stop.
        A job cut at its budget in virtual time is not: the recorder was reached (it runs on
        the tool's own line) and its silence until the cut is what it did."""
        spoke = any(self.is_recorder(e) for e in events if e.kind is not EventKind.NOTE)
        if error is None or spoke or (cut is not None and not self.driver.needs_real_time):
            return
        raise RecorderSetupError(
            f"the {self.driver.kind} could not make the recorder act (scenario "
            f"{scenario.name}, the recorder sent nothing): {error}"
        )

    def _run_served(self, scenario: Scenario, line: ServedLine) -> ScenarioRun:
        """As :meth:`_run`, in real time: the played sensors go on the served line, the
        recorder acts (the in-process one over its own RFC 2217 connection), the line
        settles, and the scenario's slice is what started on it in between."""
        played = build_sensors(scenario.sensors)
        line.settle(SETTLE)
        line.bus.set_devices(played)
        since = line.line.mark()
        begin = line.now()
        line.note(f"scenario {scenario.name}: {scenario.describe()}")
        request, absences = self.capabilities.trim(scenario.request)
        for absence in absences:
            line.note(self._absence_note(absence))
        budget = job_budget(request, played, self.job_timeout)
        line.note(budget.note())
        error, cut = None, None
        try:
            output = self._act_served(scenario, request, line, budget)
        except LinkError as exc:
            output, error = RecorderOutput(), str(exc)
        except RecorderDriverError as exc:
            output, error, cut = _failed(exc)
        ended = line.now()
        if cut is not None:
            cut.at = ended
        line.note(output_note(scenario.name, output, error, cut))
        line.settle(SETTLE)
        kept = line.line
        line.note(f"scenario {scenario.name} done; {kept.timekeeping(since, 'the scenario')}")
        end = line.now()
        line.bus.set_devices([])
        events = [e for e in list(line.transcript.events) if begin <= e.start <= end]
        self._check_setup(scenario, events, error, cut)
        return ScenarioRun(
            scenario,
            events,
            output,
            error,
            tuple(played),
            request,
            tuple(absences),
            cut,
            budget,
            ended,
        )

    def _act_served(
        self, scenario: Scenario, request: Request, line: ServedLine, budget: JobBudget
    ) -> RecorderOutput:
        if self.driver.needs_real_time:  # an external recorder connects to line.url itself
            return self.driver.act(scenario.name, request, line, budget)  # type: ignore[arg-type]
        from ..links.echo import EchoMode
        from ..links.factory import open_real_link

        # the golden recorder on the served line: no interface in between, nothing echoes
        link = open_real_link(line.url, self.uncertainty, echo=EchoMode.OFF)
        try:
            return self.driver.act(scenario.name, request, link, budget)
        finally:
            link.close()
            time.sleep(0.05)  # let the server see the disconnect before the next connection

    def harness_stderr(self) -> str | None:
        """What the recorder harness wrote to stderr, each scenario's tail under its name,
        the last ``STDERR_TAIL`` characters of them all (None: no harness, nothing kept).
        Kept in every report, as the sensor role keeps its harness's."""
        parts = [f"[{n}]\n{r.output.stderr}" for n, r in self.runs.items() if r.output.stderr]
        if not parts and not isinstance(self.driver, HarnessRecorder):
            return None
        return "\n".join(parts)[-STDERR_TAIL:]

    def close(self) -> None:
        """Stop serving (real-time ports); nothing to release on the simulated bus."""
        self.link.close()


def _failed(exc: RecorderDriverError) -> tuple[RecorderOutput, str, JobTimeout | None]:
    """What a driver's failure leaves: an empty account (a cut harness's stderr kept), the
    error's words, and the cut when the job ran out of its budget."""
    if isinstance(exc, JobTimeout):
        return RecorderOutput(stderr=exc.stderr), str(exc), exc
    return RecorderOutput(), str(exc), None


def driver_for(trigger: str | None) -> Driver | None:
    """``--trigger``: None (in-process recorder), ``interactive``, or a shell command."""
    if trigger == "interactive":
        return Interactive()
    return Trigger(trigger) if trigger else None


def check_port(port: str, trigger: str | None = None) -> bool:
    """Raise :class:`PortError` now, before a run starts, if the recorder role cannot use
    ``port`` with ``trigger`` (unknown recorder fault, real port, external recorder on sim);
    else say whether the line runs in real time (the run then takes minutes)."""
    line = open_recorder_line(port, PortOptions(), driver_for(trigger))
    try:
        return not line.link.info.virtual_time
    finally:
        line.link.close()


def _with_faults(faults: tuple[str, ...] | list[str]) -> str:
    """What the assumptions say of the golden recorder's faults: every one of a composed set
    (the report named only the first of ``short-break,no-retries``)."""
    if not faults:
        return ""
    if len(faults) == 1:
        return f" (golden recorder with fault {faults[0]})"
    return f" (golden recorder with faults {', '.join(faults)})"
