"""pytest plugin for sdi12-conform: options, the ``requirements`` marker, fixtures, and the
hooks that turn findings into test outcomes and write the reports.

Registered through the ``pytest11`` entry point, so `pytest --pyargs testcases` works on its
own; it stays inert in test runs that contain no conformance case.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import pytest

from . import gc_pace, preconditions, report_folder, whole_run
from .case import Case
from .exits import EXIT_INCOMPLETE, EXIT_INTERNAL, EXIT_NO_DEVICE, EXIT_USAGE
from .interrupts import GUARD
from .links.base import LinkError
from .links.errors import BreakUnsupported
from .offline.fixtures import heard_recorder, heard_sensors  # noqa: F401 - passive cases
from .options import UsageError, add_pytest_options, check_values
from .ports import PortError
from .preflight import check_report_dir, check_role_options
from .profiles import PROFILES
from .recorder.errors import RecorderSetupError  # not .drivers: a sensor run loads no driver
from .recorder.fixtures import recorder  # noqa: F401 - the recorder role's session fixture
from .replay.sensor import RecordingEnded
from .reports import html, writers
from .reports.html_aside import Aside, render_aside
from .reports.page_template import template_when_rendered
from .results import CaseRecord
from .run import ConformanceRun, RunOptions, given_options
from .selection import SelectionError, resolve
from .sensor.session import NoDeviceAnswered, SensorSession
from .stash import CASE
from .verdicts import Finding, Verdict

RUN = pytest.StashKey[ConformanceRun]()
OWN_GUARD = pytest.StashKey[bool]()  # the plugin (not the CLI) took over SIGINT for this run
LOCKED = pytest.StashKey[Path]()  # the report folder this run holds (report_folder.acquire)
PACE = pytest.StashKey[gc_pace.Pace]()  # the collector's pace before the run (gc_pace)
ASIDE = pytest.StashKey[Aside]()  # the process rendering report.html (reports.html_aside)
UNDEFER = pytest.StashKey[Callable[[], None]]()  # pytest-html's template reader put back
CASED = pytest.StashKey[list[pytest.Item]]()  # the items given a CASE record (detach_run)


def pytest_addoption(parser: pytest.Parser) -> None:
    add_pytest_options(parser.getgroup("sdi12-conform", "SDI-12 conformance"))


def is_conformance_session(config: pytest.Config) -> bool:
    """Whether this pytest run is the conformance suite (`--pyargs testcases...` or any
    --sdi12-* option) rather than an ordinary test session the plugin must leave alone."""
    given = [str(a) for a in config.invocation_params.args]
    return any(a.startswith("--sdi12-") for a in given) or any(
        str(a).split("/")[0].split(".")[0] == "testcases" for a in config.args
    )


@pytest.hookimpl(tryfirst=True)  # before pytest-html reads --self-contained-html
def pytest_configure(config: pytest.Config) -> None:
    if is_conformance_session(config) and hasattr(config.option, "self_contained_html"):
        config.option.self_contained_html = True  # a certificate is one file, no assets/
        undo = template_when_rendered()  # compiled where the page is made (html_aside)
        if undo is not None:
            config.stash[UNDEFER] = undo
    config.addinivalue_line(
        "markers", "requirements(*ids): the requirement IDs a conformance case judges"
    )
    config.addinivalue_line(
        "markers",
        "needs(*capabilities): link capabilities a case needs: break, unsolicited, binary",
    )
    config.addinivalue_line("markers", whole_run.MARKER_HELP)
    config.addinivalue_line("markers", preconditions.MARKER_HELP)
    config.addinivalue_line(
        "markers", "bus: a bus case, run only when the DUT shares its line with other sensors"
    )
    if not config.pluginmanager.has_plugin("sdi12-run-fixtures"):
        config.pluginmanager.register(RunFixtures(config), "sdi12-run-fixtures")
    if not config.pluginmanager.has_plugin("sdi12-whole-run-last"):
        config.pluginmanager.register(whole_run.WholeRunLast(), "sdi12-whole-run-last")
    options = RunOptions.from_config(config)
    try:
        check_values(vars(options), plugin=True)
        check_role_options(
            options.role,
            options.trigger,
            options.address,
            options.sweep,
            options.job_timeout,
        )
    except (UsageError, PortError) as exc:
        raise pytest.UsageError(str(exc)) from None
    config.stash[RUN] = ConformanceRun(options)
    given = given_options(config)
    if given is not None:  # conformance.conduct: the caller reads the run from memory
        given.run = config.stash[RUN]
        given.run.report_files = given.files
    # pytest-html as an entry point ("html": a project's own pytest run) or named with -p
    # (the judged run: conformance.suite loads no plugin it does not name)
    if any(config.pluginmanager.hasplugin(n) for n in ("html", "pytest_html.plugin")):
        aside = given is not None and given.html_aside
        config.pluginmanager.register(
            html.HtmlReportPlugin(config.stash[RUN], defer_cases=aside), "sdi12-html"
        )


def run_of(config: pytest.Config) -> ConformanceRun:
    return config.stash[RUN]


class RunFixtures:
    """A pytest plugin object, one a session: the ``sdi12_run`` and ``case`` fixtures, taken
    from the session's config and the case being run rather than from ``request``. pytest
    9 makes a new fixture definition for ``request`` (reading a lambda's signature, 40-60 us)
    each time a fixture that takes it is looked up, cached or not: four a case when these
    took it (``case`` three times, ``sdi12_run`` once through ``sensor``), ~30 ms of a
    fault-matrix row's two runs (issue 22)."""

    def __init__(self, config: pytest.Config) -> None:
        self.config = config
        self.item: pytest.Item | None = None  # the case being run

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_protocol(self, item: pytest.Item):
        self.item = item
        try:
            return (yield)
        finally:
            self.item = None

    @pytest.fixture(scope="session")
    def sdi12_run(self) -> ConformanceRun:
        return run_of(self.config)

    @pytest.fixture
    def case(self, sdi12_run: ConformanceRun) -> Case:
        """Record findings and evidence for the requirements the case's marker names."""
        if self.item is None:
            raise pytest.UsageError("`case` is a fixture of a case, asked for while it runs")
        return case_of(self.item, sdi12_run)


@pytest.fixture(scope="session")
def sensor(sdi12_run: ConformanceRun) -> SensorSession:
    """The sensor under test (sensor role), discovered once per run."""
    if sdi12_run.options.role != "sensor":
        pytest.skip("sensor-role case; this run judges a recorder")
    try:
        return sdi12_run.sensor_session()
    except NoDeviceAnswered as exc:
        reason = str(exc)
        link = sdi12_run.link
        if link is not None and not link.info.can_break:
            reason += (
                f" This {link.info.kind} link cannot send breaks, so a sensor in standby "
                "cannot be woken through it; use a serial port or rfc2217://."
            )
        sdi12_run.cut_short(reason, EXIT_NO_DEVICE)
    except PortError as exc:
        sdi12_run.cut_short(str(exc), EXIT_USAGE)
    except RecordingEnded as exc:  # a replayed capture cut short before discovery ended
        sdi12_run.cut_short(str(exc), EXIT_INCOMPLETE)
    except LinkError as exc:
        sdi12_run.cut_short(str(exc), EXIT_INTERNAL, shown=f"link error: {exc}")


#: How many events a case keeps of one piece of its evidence when it judges a recording
#: (:attr:`~.case.Case.evidence_limit`): some 20 to 40 exchanges, what a reader of the
#: report looks at; a live run's evidence is what its own stimuli made, kept whole.
RECORDING_EVIDENCE = 1000


def case_of(node: pytest.Item, sdi12_run: ConformanceRun) -> Case:
    """The ``case`` fixture's value for the case ``node``."""
    record = node.stash.get(CASE, None)
    if record is None:
        raise pytest.UsageError(f"{node.nodeid} uses `case` without @requirements")
    lacking = missing_capabilities(node, sdi12_run)
    if lacking:  # the link cannot do what the case needs: an honest INCONCLUSIVE, not a verdict
        reason = f"the {sdi12_run.link.info.kind} link cannot {' or '.join(lacking)}"
        for rid in record.requirements:
            record.findings.append(Finding(rid, Verdict.INCONCLUSIVE, reason, test=record.nodeid))
        record.summarise()
        sdi12_run.cases.append(record)
        pytest.skip(f"INCONCLUSIVE: {reason}")
    try:
        declared = preconditions.declared(node, record.requirements)
    except preconditions.PreconditionError as exc:
        raise pytest.UsageError(f"{node.nodeid}: {exc}") from None
    return Case(
        record,
        version=lambda: sdi12_run.dut_version,
        preconditions=declared,
        evidence_events=sdi12_run.report_files != (),  # no report file: no reader of them
        evidence_limit=RECORDING_EVIDENCE if getattr(sdi12_run.link, "reads_again", 0) else None,
    )


#: ``@pytest.mark.needs(...)`` names -> (LinkInfo attribute, what a reader is told it lacks)
CAPABILITIES = {
    "break": ("can_break", "send breaks"),
    "unsolicited": ("passes_unsolicited", "pass unsolicited bytes (service requests)"),
    "binary": ("binary", "pass 8N1 binary packets"),
}


def missing_capabilities(item: pytest.Item, run: ConformanceRun) -> list[str]:
    marker = item.get_closest_marker("needs")
    if marker is None or run.link is None:
        return []
    info = run.link.info
    return [CAPABILITIES[n][1] for n in marker.args if not getattr(info, CAPABILITIES[n][0])]


def case_role(item: pytest.Item) -> str | None:
    """The role a conformance case judges, from the session fixture it asks for."""
    names = getattr(item, "fixturenames", ())
    if "sensor" in names or "heard_sensors" in names:
        return "sensor"
    return "recorder" if "recorder" in names or "heard_recorder" in names else None


def keep_role_cases(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Deselect the other role's cases; none left for the chosen role is a usage error (a
    run of skips would end with exit 0 and nothing tested)."""
    role = run_of(config).options.role
    cases = [i for i in items if i.get_closest_marker("requirements")]
    other = [i for i in cases if case_role(i) not in (None, role)]
    if not other:
        return
    if len(other) == len(cases):
        found = case_role(other[0])
        raise pytest.UsageError(
            f"the selected cases judge a {found} but --sdi12-role is {role}: run "
            f"`--pyargs testcases.{role}` for a {role}, or pass --sdi12-role {found}"
        )
    items[:] = [i for i in items if i not in other]
    config.hook.pytest_deselected(items=other)


#: The marker of the cases only a bus of several sensors can make (testcases/sensor/test_bus.py).
BUS_MARKER = "bus"


def keep_bus_cases(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The bus cases run only when the DUT shares its line with other sensors
    (``RunOptions.bus``). Alone, they are not part of the suite at all, not left out of it:
    a single-sensor run is the same run it always was, not a partial one."""
    if run_of(config).options.bus:
        return
    items[:] = [i for i in items if i.get_closest_marker(BUS_MARKER) is None]


def keep_profile_cases(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``--sdi12-profile``: keep the profile's cases (a partial run, said as such)."""
    run = run_of(config)
    if run.options.profile is None:
        return
    if run.options.role != "sensor":
        raise pytest.UsageError(f"--profile {run.options.profile} selects sensor cases")
    profile = PROFILES[run.options.profile]
    dropped = [i for i in items if _requirements_of(i) and i.name not in profile.cases]
    items[:] = [i for i in items if i not in dropped]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
    run.selection.how.append(f"--profile {profile.name}")


def keep_selected_requirements(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``--sdi12-req``: keep the cases that judge one of the named requirements."""
    run = run_of(config)
    if not run.options.requirements:
        return
    try:
        wanted = resolve(run.options.role, run.options.requirements)
    except SelectionError as exc:
        raise pytest.UsageError(str(exc)) from None
    dropped = [i for i in items if _requirements_of(i) and not wanted & set(_requirements_of(i))]
    items[:] = [i for i in items if i not in dropped]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
    run.selection.how += [f"--req {text}" for text in run.options.requirements]


def _requirements_of(item: pytest.Item) -> tuple[str, ...]:
    marker = item.get_closest_marker("requirements")
    return tuple(marker.args) if marker else ()


def pytest_deselected(items: list[pytest.Item]) -> None:
    """Cases of the run's role left out by -k or --req make it a partial run."""
    if not items:
        return
    run = run_of(items[0].config)
    for item in items:
        if _requirements_of(item) and case_role(item) in (None, run.options.role):
            run.selection.left_out.update(_requirements_of(item))


def pytest_collection_finish(session: pytest.Session) -> None:
    run = run_of(session.config)
    for item in session.items:
        run.selection.kept.update(_requirements_of(item))
    keyword = session.config.getoption("keyword", "")
    if run.selection.partial and keyword:
        run.selection.how.insert(0, f"-k {keyword}")


def check_reports_writable(config: pytest.Config) -> None:
    """The report folder is writable and this run's alone (another run still writing there
    is refused), until :func:`pytest_unconfigure` lets it go."""
    try:
        path = check_report_dir(run_of(config).report_dir())
        report_folder.acquire(path)
    except (UsageError, OSError) as exc:
        raise pytest.UsageError(f"--sdi12-report-dir: {exc}") from None
    config.stash[LOCKED] = path


def stable_id(item: pytest.Item) -> str:
    """``testcases.sensor.test_4_4_12_crc::test_crc_presence``: the same wherever the suite
    is installed or run from (pytest's node IDs are relative to its rootdir)."""
    module = getattr(getattr(item, "module", None), "__name__", None)
    if module is None:
        return item.nodeid
    inner = item.nodeid.split("::", 1)[1] if "::" in item.nodeid else item.name
    return f"{module}::{inner}"


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not any(item.get_closest_marker("requirements") for item in items):
        return  # an ordinary test session
    keep_role_cases(config, items)
    keep_bus_cases(config, items)
    keep_profile_cases(config, items)
    keep_selected_requirements(config, items)
    check_reports_writable(config)
    if not GUARD.installed:
        GUARD.install()  # `pytest --pyargs testcases` on its own: same Ctrl-C policy as the CLI
        config.stash[OWN_GUARD] = True
    if PACE not in config.stash:
        config.stash[PACE] = gc_pace.slow_down()  # the suite is loaded: the run starts
    give_case_records(config, items)


def give_case_records(config: pytest.Config, items: list[pytest.Item]) -> None:
    """A fresh :class:`CaseRecord` on every conformance case among ``items``, for the run
    about to start (one session judging many runs gives each its own: ``many_runs``)."""
    for item in items:
        marker = item.get_closest_marker("requirements")
        if marker is None:
            continue
        doc = (getattr(item, "function", None).__doc__ or "").strip()
        item.stash[CASE] = CaseRecord(
            nodeid=stable_id(item),
            name=item.name,
            requirements=tuple(marker.args),
            description=" ".join(doc.split()),
        )
        config.stash.setdefault(CASED, []).append(item)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None):
    """Ctrl-C stops a case at once (pytest reports INTERRUPTED); outside cases it waits."""
    if not GUARD.installed or CASE not in item.stash:
        return (yield)
    with GUARD.armed():
        return (yield)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item):
    record = item.stash.get(CASE, None)
    if record is None:
        return (yield)
    run = run_of(item.config)
    run.cases.append(record)
    started = time.perf_counter()
    before = _transcript_length(run)
    first_event = 0 if whole_run.is_whole_run(item) else before
    clock = run.link.now() if run.link is not None else None
    try:
        result = yield
    except (pytest.skip.Exception, pytest.fail.Exception, pytest.exit.Exception, KeyboardInterrupt):
        raise
    except BreakUnsupported as exc:  # the case needs a break of its own making
        _inconclusive(record, f"this case presents its own breaks and the link cannot: {exc}")
        pytest.skip(f"INCONCLUSIVE: the link cannot send breaks ({exc})")
    except RecorderSetupError as exc:  # a trigger that cannot work: stop, blame the setup
        _error(record, f"test setup failed: {exc}")
        run.cut_short(f"test setup failed: {exc}", EXIT_USAGE)
    except RecordingEnded as exc:  # a replayed capture cut short: the rest is left open
        _inconclusive(record, str(exc))
        run.cut_short(str(exc), EXIT_INCOMPLETE)
    except LinkError as exc:  # the port failed: stop the run, keep the report (exit 3)
        _error(record, f"link failed: {exc}")
        run.cut_short(f"link failed: {exc}", EXIT_INTERNAL)
    except Exception as exc:  # the tool failed: ERROR, never hidden as a FAIL or a PASS
        _error(record, f"tool error: {type(exc).__name__}: {exc}")
        raise
    finally:
        record.duration = time.perf_counter() - started
        record.window = (first_event, _transcript_length(run))
        record.added = (before, record.window[1])
        if clock is not None and run.link is not None:
            record.bus_s = run.link.now() - clock
    if run.session is not None:  # recorder role: what its declaration excuses
        run.session.apply_declaration(record)
    verdict = record.summarise()
    if not record.findings:
        _error(record, "case produced no finding (a check that cannot fail is a defect)")
        pytest.fail("no finding recorded", pytrace=False)
    if isinstance(run.session, SensorSession) and run.session.lost:
        run.cut_short(_lost(record, run.session.lost), EXIT_NO_DEVICE)
    if verdict in (Verdict.FAIL, Verdict.ERROR):
        lines = [
            f"{f.verdict} {f.requirement}: {f.detail}"
            for f in record.findings
            if f.verdict in (Verdict.FAIL, Verdict.ERROR)
        ]
        pytest.fail("\n".join(lines), pytrace=False)
    if verdict in (Verdict.NA, Verdict.INCONCLUSIVE):
        reasons = sorted({f.detail for f in record.findings if f.verdict is verdict})
        pytest.skip(f"{verdict}: {'; '.join(reasons)}")
    return result


def _lost(record: CaseRecord, note: str) -> str:
    """Why the run stops after a case that lost the sensor (:attr:`SensorSession.lost`):
    this case's verdicts and the ones before it stand, no later case runs."""
    case = record.nodeid.rsplit("::", 1)[-1]
    return (
        f"the sensor was lost in {case}: {note}; every later case would judge the silence "
        "of an address it no longer answers, so the run stops here (the verdicts so far "
        "stand; a declaration with address_change = false judges the rest without moving it)"
    )


def _transcript_length(run: ConformanceRun) -> int:
    return len(run.link.transcript) if run.link is not None else 0


def _inconclusive(record: CaseRecord, detail: str) -> None:
    judged = {f.requirement for f in record.findings}
    for rid in record.requirements:
        if rid not in judged:
            record.findings.append(Finding(rid, Verdict.INCONCLUSIVE, detail, test=record.nodeid))
    record.summarise()


def _error(record: CaseRecord, detail: str) -> None:
    for rid in record.requirements:
        record.findings.append(Finding(rid, Verdict.ERROR, detail, test=record.nodeid))
    record.summarise()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo):
    report = yield
    record = item.stash.get(CASE, None)
    if record is not None and report.when == "call":
        report.user_properties.append(("requirements", " ".join(record.requirements)))
        report.user_properties.append(("verdict", str(record.verdict)))
        report.sdi12_verdict = str(record.verdict)
        report.sdi12_requirements = record.requirements
    return report


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if RUN in session.config.stash:  # else each run was finished as it ended (many_runs)
        finish_run(session, exitstatus)


def finish_run(session: pytest.Session, exitstatus: int) -> None:
    """The run's end once its cases are done or it was stopped (``exitstatus``: pytest's for
    the session, or the run's own in a session judging many): decide, write the reports,
    close the link."""
    run = run_of(session.config)
    guarded = GUARD.installed
    late_interrupt = guarded and GUARD.close()  # from here on Ctrl-C cannot change the run
    if late_interrupt and not run.stop_reason:
        run.stop_reason = "run interrupted (Ctrl-C)"
    if not run.active and run.session is None and not run.stop_reason:
        return  # no conformance case ran: an ordinary test session
    stopped = exitstatus in (pytest.ExitCode.INTERRUPTED, EXIT_NO_DEVICE, EXIT_INTERNAL, EXIT_USAGE)
    interrupted = late_interrupt or stopped
    if interrupted and not run.stop_reason:
        run.stop_reason = "run interrupted"
    if session.shouldstop or session.shouldfail:
        run.complete = False
    run.finish(complete=not interrupted)
    ours = session.config.pluginmanager.get_plugin("sdi12-html")
    if ours is not None and ours.defer_cases:  # report.html by another process, at once
        aside = render_aside(session, ours)
        if aside is not None:
            session.config.stash[ASIDE] = aside
    writers.write_reports(run, run.report_dir())
    run.close()


def pytest_unconfigure(config: pytest.Config) -> None:
    aside = config.stash.get(ASIDE, None)
    if aside is not None:  # pytest-html waits for it; here too if its session end did not run
        aside.wait()
    undo = config.stash.get(UNDEFER, None)
    if undo is not None:
        undo()
    pace = config.stash.get(PACE, None)
    if pace is not None:
        gc_pace.restore(pace)
    release_report_folder(config)
    if config.stash.get(OWN_GUARD, False):
        GUARD.uninstall()
        GUARD.reset()
    detach_run(config)


def release_report_folder(config: pytest.Config) -> None:
    """Let go of the report folder :func:`check_reports_writable` took for the run."""
    locked = config.stash.get(LOCKED, None)
    if locked is not None:
        report_folder.release(locked)
        del config.stash[LOCKED]


def detach_run(config: pytest.Config) -> None:
    """Let go of the run at the session's very end. pytest's config, session and items hold
    each other in reference cycles, so whatever they reference lives until the cyclic
    collector walks it: the whole run (its transcript's 10^4..10^5 events, the case records
    and their findings), a fault-matrix process's dozens of runs piling up for full
    collections over all of them. Dropped here (with ``GivenOptions.run`` in
    :func:`conformance.conduct.conduct`), the run is freed by reference counting as soon as
    its caller lets it go; the run itself holds no cycle back to pytest."""
    for item in config.stash.get(CASED, ()):
        if CASE in item.stash:
            del item.stash[CASE]
    for key in (CASED, RUN):
        if key in config.stash:
            del config.stash[key]
