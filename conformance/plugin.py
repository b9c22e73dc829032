"""pytest plugin for sdi12-conform: options, the ``requirements`` marker, fixtures, and the
hooks that turn findings into test outcomes and write the reports.

Registered through the ``pytest11`` entry point, so `pytest --pyargs testcases` works on its
own; it stays inert in test runs that contain no conformance case.
"""

from __future__ import annotations

import time

import pytest

from .case import Case
from .links.base import LinkError
from .links.errors import BreakUnsupported
from .ports import PortError
from .recorder.fixtures import recorder  # noqa: F401 - the recorder role's session fixture
from .results import CaseRecord
from .run import ConformanceRun, RunOptions
from .sensor_session import NoDeviceAnswered, SensorSession
from .verdicts import Finding, Verdict

RUN = pytest.StashKey[ConformanceRun]()
CASE = pytest.StashKey[CaseRecord]()
EXIT_NO_DEVICE = 5


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("sdi12-conform", "SDI-12 conformance")
    group.addoption(
        "--sdi12-port",
        default="sim",
        help="DUT port: sim, sim://?faults=..., COM3, /dev/ttyUSB0, rfc2217://h:p",
    )
    group.addoption(
        "--sdi12-role",
        default="sensor",
        choices=("sensor", "recorder"),
        help="what the DUT is (the tool plays the other side)",
    )
    group.addoption("--sdi12-address", default=None, help="DUT address (default: ask with ?!)")
    group.addoption(
        "--sdi12-version",
        default=None,
        help="force the rule set (1.3 or 1.4) instead of reading it from aI!",
    )
    group.addoption("--sdi12-declaration", default=None, help="DUT declaration (TOML)")
    group.addoption("--sdi12-report-dir", default=None, help="where verdicts.json etc. go")
    group.addoption(
        "--sdi12-strict",
        action="store_true",
        default=False,
        help="treat WARN (SHOULD violations) as non-compliance",
    )
    group.addoption(
        "--sdi12-trigger",
        default=None,
        help="recorder role: shell command run per scenario (or 'interactive' to prompt)",
    )
    group.addoption(
        "--sdi12-timing-uncertainty-ms",
        type=float,
        default=None,
        help="widen the link's measured timestamp uncertainty (never narrows it)",
    )
    group.addoption(
        "--sdi12-echo",
        default="auto",
        choices=("auto", "on", "off"),
        help="real links: the interface echoes the tool's characters (auto: find out)",
    )
    group.addoption(
        "--sdi12-direction",
        default="none",
        choices=("none", "rts", "dtr"),
        help="real links: raise this line for the tool's transmissions (transceiver enable)",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "requirements(*ids): the requirement IDs a conformance case judges"
    )
    config.addinivalue_line(
        "markers",
        "needs(*capabilities): link capabilities a case needs: break, unsolicited, binary",
    )
    config.stash[RUN] = ConformanceRun(RunOptions.from_config(config))
    if config.pluginmanager.hasplugin("html"):
        from .reports import html

        config.pluginmanager.register(html.HtmlReportPlugin(config.stash[RUN]), "sdi12-html")


def run_of(config: pytest.Config) -> ConformanceRun:
    return config.stash[RUN]


@pytest.fixture(scope="session")
def sdi12_run(request: pytest.FixtureRequest) -> ConformanceRun:
    return run_of(request.config)


@pytest.fixture(scope="session")
def sensor(sdi12_run: ConformanceRun) -> SensorSession:
    """The sensor under test (sensor role), discovered once per run."""
    if sdi12_run.options.role != "sensor":
        pytest.skip("sensor-role case; this run judges a recorder")
    try:
        return sdi12_run.sensor_session()
    except NoDeviceAnswered as exc:
        sdi12_run.complete = False
        sdi12_run.stop_reason = str(exc)
        link = sdi12_run.link
        if link is not None and not link.info.can_break:
            sdi12_run.stop_reason += (
                f" This {link.info.kind} link cannot send breaks, so a sensor in standby "
                "cannot be woken through it; use a serial port or rfc2217://."
            )
        pytest.exit(sdi12_run.stop_reason, returncode=EXIT_NO_DEVICE)
    except PortError as exc:
        sdi12_run.complete = False
        sdi12_run.stop_reason = str(exc)
        pytest.exit(str(exc), returncode=4)
    except LinkError as exc:
        sdi12_run.complete = False
        sdi12_run.stop_reason = str(exc)
        pytest.exit(f"link error: {exc}", returncode=3)


@pytest.fixture
def case(request: pytest.FixtureRequest, sdi12_run: ConformanceRun) -> Case:
    """Record findings and evidence for the requirements the case's marker names."""
    record = request.node.stash.get(CASE, None)
    if record is None:
        raise pytest.UsageError(f"{request.node.nodeid} uses `case` without @requirements")
    lacking = missing_capabilities(request.node, sdi12_run)
    if lacking:  # the link cannot do what the case needs: an honest INCONCLUSIVE, not a verdict
        reason = f"the {sdi12_run.link.info.kind} link cannot {' or '.join(lacking)}"
        for rid in record.requirements:
            record.findings.append(Finding(rid, Verdict.INCONCLUSIVE, reason, test=record.nodeid))
        record.summarise()
        sdi12_run.cases.append(record)
        pytest.skip(f"INCONCLUSIVE: {reason}")
    return Case(record, version=lambda: sdi12_run.dut_version)


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


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        marker = item.get_closest_marker("requirements")
        if marker is None:
            continue
        doc = (getattr(item, "function", None).__doc__ or "").strip()
        item.stash[CASE] = CaseRecord(
            nodeid=item.nodeid,
            name=item.name,
            requirements=tuple(marker.args),
            description=" ".join(doc.split()),
        )


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item):
    record = item.stash.get(CASE, None)
    if record is None:
        return (yield)
    run = run_of(item.config)
    run.cases.append(record)
    started = time.perf_counter()
    try:
        result = yield
    except (pytest.skip.Exception, pytest.fail.Exception, pytest.exit.Exception, KeyboardInterrupt):
        raise
    except BreakUnsupported as exc:  # the case needs a break of its own making
        _inconclusive(record, f"this case presents its own breaks and the link cannot: {exc}")
        pytest.skip(f"INCONCLUSIVE: the link cannot send breaks ({exc})")
    except LinkError as exc:  # the port failed: stop the run, keep the report (exit 3)
        _error(record, f"link failed: {exc}")
        run.complete = False
        run.stop_reason = f"link failed: {exc}"
        pytest.exit(f"link failed: {exc}", returncode=3)
    except Exception as exc:  # the tool failed: ERROR, never hidden as a FAIL or a PASS
        _error(record, f"tool error: {type(exc).__name__}: {exc}")
        raise
    finally:
        record.duration = time.perf_counter() - started
    verdict = record.summarise()
    if not record.findings:
        _error(record, "case produced no finding (a check that cannot fail is a defect)")
        pytest.fail("no finding recorded", pytrace=False)
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
    run = run_of(session.config)
    if not run.active and run.session is None and not run.stop_reason:
        return  # no conformance case ran: an ordinary test session
    interrupted = exitstatus in (pytest.ExitCode.INTERRUPTED, EXIT_NO_DEVICE, 3, 4)
    if interrupted and not run.stop_reason:
        run.stop_reason = "run interrupted"
    if session.shouldstop or session.shouldfail:
        run.complete = False
    run.finish(complete=not interrupted)
    from .reports import verdicts_json

    verdicts_json.write(run, run.report_dir())
    run.close()
