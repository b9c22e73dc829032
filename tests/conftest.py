"""Suite-wide hooks for the tool's own tests.

Real-time tests (RFC 2217 on loopback, bench runs, the emulator process) cannot judge a
device when the shared machine is too busy to keep real time: they skip rather than give a
false verdict. A skip like that must not vanish among ordinary skips, so every such skip says
``the machine was too busy`` and the figure it measured (how late the served line fell, or the
timing uncertainty that left a verdict INCONCLUSIVE), and the hook below lists them in a
section of their own at the end of the run, even with ``-q`` and under pytest-xdist.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import HealthCheck, settings

# The tool's own property tests check what is computed, never how fast: in CI they share two
# cores with real-time tests and a niced session of thousands of others (load 20 seen), where
# hypothesis's 200 ms deadline and its slow-generation health check failed tests whose
# properties held. The tool's exploration sets its own settings and is not touched by this.
settings.register_profile("project", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("project")

# Runs on real-time links plan first by default (a dry run of ~5 s of CPU); the tool's own
# tests start dozens of those, side by side with real-time ones, so they run unplanned unless
# a test asks (--plan always, tests/commands/test_plan.py). Inherited by every CLI subprocess.
os.environ.setdefault("SDI12_PLAN", "never")

pytest_plugins = ["pytester"]  # tests/test_conftest.py runs tiny sessions

#: The phrase every busy-machine skip reason carries (with its measured figure after it).
BUSY = "the machine was too busy"
TITLE = "skipped because the machine was busy"


def skip_reason(report: pytest.TestReport) -> str | None:
    """The reason of a skip report: a ``(path, line, reason)`` tuple in this process, a
    list once pytest-xdist has carried it over from a worker as JSON."""
    longrepr = report.longrepr
    if isinstance(longrepr, tuple | list) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix("Skipped: ")
    return None


def busy_skips(reports: list[pytest.TestReport]) -> list[tuple[str, str]]:
    """``(node id, reason)`` of each skip taken because the machine was too busy."""
    found = []
    for report in reports:
        reason = skip_reason(report)
        if reason is not None and BUSY in reason:
            found.append((report.nodeid, reason))
    return found


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    found = busy_skips(terminalreporter.stats.get("skipped", []))
    if not found:
        return
    terminalreporter.write_sep("=", f"{TITLE}: {len(found)}", yellow=True)
    for nodeid, reason in found:
        terminalreporter.write_line(f"{nodeid}: {reason}")
