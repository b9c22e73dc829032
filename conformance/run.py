"""One conformance run: options, the link, the session, the case records, and the outputs.

Created by the plugin at configure time; the link is opened lazily by the first case that needs
the DUT, so `pytest --pyargs testcases` with nothing selected never touches a port.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from . import __version__, root_causes
from .declaration import Declaration, load_declaration, normalise_version
from .dut import Session
from .judges.timing import recheck, undecide_after_late_line
from .links.base import BusEnd, Link, LinkError
from .options import run_option_values
from .ports import is_sim, open_port
from .profiles import PROFILES
from .protocol.version import V14
from .replay.recording import options_note
from .report_folder import run_folder
from .results import CaseRecord, RequirementResult, aggregate, overall
from .selection import Selection
from .sensor.session import SensorSession

if TYPE_CHECKING:  # the recorder role's runner: imported by the run that plays it
    from .recorder.scenario_runner import RecorderSession


@dataclass
class RunOptions:
    """Every option of one run (the CLI's, the plugin's and the callers' of
    :func:`conformance.conduct.conduct`), once, as the run reads them."""

    port: str = "sim"
    role: str = "sensor"
    address: str | None = None
    version: str | None = None
    declaration: str | None = None
    report_dir: str | None = None
    strict: bool = False
    timing_uncertainty_ms: float | None = None
    trigger: str | None = None  # recorder role: shell command (or "interactive") per scenario
    job_timeout: float | None = None  # recorder role: bus seconds per job (default per scenario)
    echo: str = "auto"  # real links: does the interface echo the tool's characters
    direction: str = "none"  # real links: the modem line that enables the tool's driver
    requirements: tuple[str, ...] = ()  # --req: requirement IDs or clauses to judge
    keyword: str | None = None  # -k: the cases selected by name
    sweep: str | None = None  # recorder role: tolerance sweeps to run ("reply,wake")
    profile: str | None = None  # a named selection of the sensor suite (conformance.profiles)
    #: every sensor on the line as (address, its aI! reply or None), when the DUT shares it
    #: with others (``--address 0,1,3`` / ``all``: conformance.commands.bus); empty: alone
    bus: tuple[tuple[str, str | None], ...] = ()

    @property
    def timing_uncertainty(self) -> float | None:
        """``--timing-uncertainty-ms`` in seconds, as the port openers take it."""
        ms = self.timing_uncertainty_ms
        return None if ms is None else ms / 1000

    @classmethod
    def from_values(cls, values: dict[str, Any], keyword: str | None = None) -> RunOptions:
        """From RunOptions field -> value (as :mod:`conformance.options` reads them)."""
        values = dict(values)
        values["requirements"] = tuple(values.get("requirements") or ())
        return cls(**values, keyword=keyword or None)

    @classmethod
    def from_config(cls, config: Any) -> RunOptions:
        """From pytest's own command line: ``pytest --pyargs testcases.sensor --sdi12-...``
        (a run started by :func:`conformance.conduct.conduct` hands its options over whole)."""
        given = given_options(config)
        if given is not None:
            return given.options
        return cls.from_values(run_option_values(config.getoption), config.getoption("keyword"))


class GivenOptions:
    """A pytest plugin object that carries a run's options into the pytest session, so the
    conformance plugin takes them as they are instead of parsing them back from flags; it
    is also where the plugin leaves the :class:`ConformanceRun` it made, for the caller.

    ``files``: which of the run's report files (``reports.writers.REPORT_WRITERS`` by name) it
    writes; None: all of them. A fault matrix's runs write none: a row reads its verdicts
    (:meth:`ConformanceRun.verdict_lines`) and its events from memory, and a run's verdicts
    do not depend on which files it writes. ``html_aside``: report.html may be rendered by a
    forked process while this one writes the rest (:mod:`conformance.reports.html_aside`)."""

    def __init__(self, options: RunOptions) -> None:
        self.options = options
        self.files: tuple[str, ...] | None = None
        self.run: ConformanceRun | None = None
        #: report.html may be rendered by a forked process (reports.html_aside): a caller
        #: that owns its process to the end says so
        self.html_aside = False


def given_options(config: Any) -> GivenOptions | None:
    """The options handed to this pytest session, if a caller handed any."""
    for plugin in config.pluginmanager.get_plugins():
        if isinstance(plugin, GivenOptions):
            return plugin
    return None


def now_iso() -> str:
    return dt.datetime.now(dt.UTC).isoformat(timespec="seconds")


@dataclass
class ConformanceRun:
    """One run as it happens and after: its options, link, session and case records; the
    reports are written from it, and its verdicts document stays on it for the caller."""

    options: RunOptions
    started: str = field(default_factory=now_iso)
    finished: str | None = None
    cases: list[CaseRecord] = field(default_factory=list)
    link: BusEnd | None = None  # a link; a served line or a recording (nothing transmits)
    session: Session | None = None  # the sensor, recorder or passive session
    complete: bool = True
    stop_reason: str = ""
    declaration: Declaration | None = None
    results: list[RequirementResult] | None = None
    verdict: str | None = None
    selection: Selection = field(default_factory=Selection)  # -k / --req: a partial run
    document: dict[str, Any] | None = None  # verdicts.json as written: the CLI reads this
    #: recorder role, --sweep: the tolerance sweeps (conformance.recorder.sweep); informational,
    #: never part of a verdict. None: not asked for (verdicts.json then has no "sweeps" key)
    sweeps: list[Any] | None = None
    #: the report files the run writes when it ends (None: every one; see GivenOptions)
    report_files: tuple[str, ...] | None = None

    def verdict_lines(self) -> dict[str, Any] | None:
        """What a fault matrix reads of verdicts.json, taken from the run itself, with the
        very expressions ``reports.verdicts_json.build`` writes them with (None before the
        run finished): ``summary.verdict``, ``run.link``, ``run.stop_reason`` and each
        requirement's ``id``, ``verdict`` and its findings' ``verdict`` and ``detail`` (a
        combination's reader's why). A matrix's runs write no verdicts.json
        (``tests/matrices/test_verdict_lines.py`` compares the two)."""
        if self.results is None:
            return None
        return {
            "run": {"link": self.link_description(), "stop_reason": self.stop_reason or None},
            "summary": {"verdict": self.verdict},
            "requirements": [
                {
                    "id": r.requirement.id,
                    "verdict": str(r.verdict),
                    "findings": [
                        {"verdict": str(f.verdict), "detail": f.detail} for f in r.findings
                    ],
                }
                for r in self.results
            ],
        }

    def __post_init__(self) -> None:
        if self.options.declaration:
            self.declaration = load_declaration(self.options.declaration)

    @property
    def active(self) -> bool:
        """Whether any conformance case ran (the plugin stays silent for ordinary tests)."""
        return bool(self.cases)

    def open_link(self) -> Link:
        """The sensor role's link, opened the first time it is asked for."""
        if self.link is None:
            opened = open_port(
                self.options.port,
                echo=self.options.echo,
                direction=self.options.direction,
                timing_uncertainty=self.options.timing_uncertainty,
            )
            self.link = opened.link
            if self.declaration is None:
                self.declaration = opened.declaration
            self.note_options()
        assert isinstance(self.link, Link), "the sensor role transmits on a link"
        return self.link

    def note_options(self) -> None:
        """Open the transcript with how this run was made (options and link), so that
        ``sdi12-conform judge`` can repeat its stimuli exactly when it judges it again."""
        if self.link is None:
            return
        options = asdict(self.options) | {"link": asdict(self.link.info)}
        if not self.options.bus:
            del options["bus"]  # a DUT alone on its line: the note as it always was
        self.link.transcript.add(options_note(options, self.link.now()))

    def sensor_session(self) -> SensorSession:
        if self.session is None:
            link = self.open_link()
            session = SensorSession(
                link,
                address=self.options.address,
                declaration=self.declaration,
                forced_version=normalise_version(self.options.version)
                if self.options.version
                else None,
                bus=self.options.bus,
            )
            self.session = session
            if self.options.profile is not None:
                profile = PROFILES[self.options.profile]
                session.groups = profile.groups
                session.assumptions.append(profile.note())
            session.discover()
        assert isinstance(self.session, SensorSession)
        return self.session

    def recorder_session(self) -> RecorderSession:
        """The recorder role's scenario runner (conformance.recorder.scenario_runner, imported
        here: a sensor-role process never loads the recorder role, about 45 ms of its start)."""
        from .recorder.scenario_runner import RecorderSession, driver_for

        if self.session is None:
            opts = self.options
            declared = self.declaration.sdi12_version if self.declaration else None
            version = normalise_version(opts.version) if opts.version else declared or V14
            driver = driver_for(opts.trigger)
            session = RecorderSession(
                opts.port,
                version=version,
                driver=driver,
                timing_uncertainty=opts.timing_uncertainty,
                declaration=self.declaration,
                job_timeout=opts.job_timeout,
            )
            self.session, self.link = session, session.link
            self.note_options()
        assert isinstance(self.session, RecorderSession)
        return self.session

    def cut_short(self, reason: str, code: int, *, shown: str | None = None) -> NoReturn:
        """Stop the whole pytest session now with exit status ``code`` (exits.py), the run
        left incomplete for ``reason``: the reports are still written, and say why."""
        import pytest

        self.complete = False
        self.stop_reason = reason
        pytest.exit(shown or reason, returncode=code)

    @property
    def dut_version(self) -> str | None:
        return self.session.version if self.session else None

    def finish(self, complete: bool) -> list[RequirementResult]:
        self._run_sweeps(complete)
        self._check_link()
        self.complete = self.complete and complete
        self.finished = now_iso()
        self._recheck_timing()
        self._guard_served_line()
        self.results = aggregate(self.options.role, self.cases, self.selection.not_selected())
        root_causes.link(self.results)
        self.verdict = overall(self.results, strict=self.options.strict, complete=self.complete)
        unjudged = sum(1 for r in self.results if r.selected and not r.judged)
        if unjudged and not self.stop_reason:
            self.stop_reason = (
                f"{unjudged} testable requirement(s) of the selected cases not judged"
            )
        return self.results

    def _run_sweeps(self, complete: bool) -> None:
        """``--sweep``: after every case judged, the tolerance sweeps on the same bus and
        recorder. They come after the cases, so no case's transcript slice or verdict can
        change; an interrupted run (or one whose recorder never got going) sweeps nothing."""
        if not self.options.sweep or self.options.role != "recorder":
            return
        from .recorder.sweep import parse_kinds, run_sweeps

        self.sweeps = []
        if complete and self.complete and self.session is not None:
            self.sweeps = run_sweeps(self.session, parse_kinds(self.options.sweep))

    def _check_link(self) -> None:
        """A link that can vouch for its records only at the end (a harness, whose answers
        could have fallen out of step) is asked now, before the verdicts are drawn."""
        if self.link is None:
            return
        try:
            self.link.check_records(self.cases)
        except LinkError as exc:
            self.complete = False
            self.stop_reason = self.stop_reason or f"link failed: {exc}"

    def _recheck_timing(self) -> None:
        """Timing verdicts must hold for the uncertainty the whole run measured, not only
        for the figure known when each case judged (real links measure as they go)."""
        if self.link is None or self.link.info.virtual_time or self.session is None:
            return
        uncertainty = self.session.uncertainty
        for case in self.cases:
            recheck(case.findings, uncertainty)

    def _guard_served_line(self) -> None:
        """Recorder role on a served line (``rfc2217-serve://``): if the line this tool kept
        in real time fell behind its schedule where no note of it says so, no FAIL or WARN of
        the run can be trusted to be the recorder's own (a false FAIL is what a busy host
        would otherwise give). Where the line noted every late frame (truth34: it notes
        them all), only what the notes can explain is held: a case stands where none of its
        scenarios lies near a note (:func:`~.judges.recorder.stalls.late_near`); in one that
        does, the rules whose judges read the notes stand as judged for a recorder in a
        process of its own, and for one in the tool's process, whose threads the host held
        up around a stall where nothing notes it (base-s69's paused clean run: a 1.15 ms
        break 184 ms after a note), only where what they name lies far from every note
        (:func:`~.judges.recorder.stalls.stamped_far`)."""
        late = self.session.worst_lateness() if self.session is not None else 0.0
        if late <= 0.0:
            return  # nothing fell behind: every line but a served one (and its package's
            # servers stay unloaded, as the rest of a run needs none of them)
        from .emulator_server.realtime import LATE_NOTICE
        from .judges.recorder.stalls import READ_STALLS, late_near, stamped_far

        if late <= LATE_NOTICE:
            return
        # lateness the line's own stall notes explain all of: the rules whose judges read
        # those notes (each deviation a noted stall covers held, naming it) stand as judged
        session = self.session
        assert session is not None
        explained = session.unexplained_lateness() <= LATE_NOTICE
        stalls = session.noted_stalls() if explained else []
        apart = explained and not session.recorder_in_process()
        for case in self.cases:
            findings = case.findings
            if explained and not late_near(case.evidence, stalls):
                continue
            if apart:
                findings = [f for f in findings if f.requirement not in READ_STALLS]
            elif explained:  # in the tool's process: only what stands far from every note
                findings = [
                    f
                    for f in findings
                    if f.requirement not in READ_STALLS or not stamped_far(f, stalls)
                ]
            undecide_after_late_line(findings, late, LATE_NOTICE)

    def report_dir(self) -> Path:
        """The run's folder: the one named, or a new one of its own (never another run's)."""
        path = run_folder(self.options.report_dir, self.options.role)
        path.mkdir(parents=True, exist_ok=True)
        self.options.report_dir = str(path)
        return path

    def link_description(self) -> dict[str, Any]:
        info = self.link.info if self.link else None
        uncertainty = self.session.uncertainty if self.session else None
        if info is None:
            return {
                "kind": "sim" if is_sim(self.options.port) else "unknown",
                "can_break": None,
                "timing_uncertainty_ms": None,
            }
        found: dict[str, Any] = {
            "kind": info.kind,
            "can_break": info.can_break,
            "timing_uncertainty_ms": round((uncertainty or 0.0) * 1000, 3),
        }
        if self.session is not None:  # the tool recorder's collisions, a harness's stderr
            found |= self.session.link_facts()
        bench = self.link.describe()
        if bench is not None:  # a real bench: echo, how breaks are made, measured timing
            found["bench"] = bench
        if self.link.runs_harness:  # exec:/unix: the harness's own log (null: a socket's)
            found["harness_stderr"] = self.link.harness_stderr()
        return found

    def close(self) -> None:
        if self.link is not None:
            self.link.close()


TOOL_IDENTITY = {"name": "sdi12-conform", "version": __version__}
