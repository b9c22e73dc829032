"""Suite-wide hooks for the tool's own tests.

Real-time tests (RFC 2217 on loopback, bench runs, the emulator process) cannot judge a
device when the shared machine is too busy to keep real time: they skip rather than give a
false verdict. A skip like that must not vanish among ordinary skips, so every such skip says
``the machine was too busy`` and the figure it measured (how late the served line fell, or the
timing uncertainty that left a verdict INCONCLUSIVE), and the hook below lists them in a
section of their own at the end of the run, even with ``-q`` and under pytest-xdist.

The modules are handed out longest first (:data:`FIRST`), so that CI's workers do not end the
session on a long module started last.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path

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


# The order the test modules are handed out in: the long ones first.
#
# CI's not-real-time session (.ci/test) runs under pytest-xdist with --dist loadfile, which
# gives each worker a whole module at a time, in the order of its work queue. By default
# xdist 3.8 orders that queue by the number of tests a module holds, so the sensor matrix's
# rows modules (31 tests, 53-67 s of CPU each) started about half-way through, and the
# modules that mostly wait on a line paced in real time (hostile devices on socket://) last:
# a tail with a core idle. .ci/test passes --no-loadscope-reorder, so the queue follows the
# collection order, and the hook below puts the modules of FIRST first, in that order; every
# other module keeps its place after them. Only the order changes: every test still runs, in
# the same module, with the same fixtures.
#
# Measured (stop 37, shared 2-core machine, benchmarks/ci_schedule.py's plugin): each module's
# CPU in the not-real-time session, its own and its subprocesses', with its share of the
# session's 788 s; the waiting modules with the wall time they took alone.

#: Modules that mostly wait (a CLI subprocess judging a device paced at 1200 baud on
#: ``socket://``): first, so their waits overlap the others' CPU instead of ending the session.
WAITING = (
    "tests/e2e/test_hostile_devices.py",  # 13 s of CPU, 167 s of wall alone
    "tests/e2e/test_hostile_replies.py",  # 4 s of CPU, 94 s of wall alone
)

#: Then the modules that take most CPU, most first. Issue 22's ci7 round moved up the modules
#: that CI's slowest-durations list showed long on the stop-53 machine (its quiet clean-clone
#: run, wall under the session's load; a loaded run's figures about twice these): the rows
#: modules 1 and 2 by their figures, and modules that had grown since stop 37's CPU figures
#: (below: stop 37's CPU, then "ci7:" CI's wall, halved where measured loaded), so that none
#: of them starts in the session's last minute.
LONGEST = (
    "tests/matrices/test_sensor_matrix_rows_1.py",  # 61 s (7.7%); ci7: 129 s of wall in CI
    "tests/matrices/test_sensor_matrix_rows_2.py",  # 53 s (6.7%); ci7: 124 s
    "tests/matrices/test_sensor_matrix_rows_3.py",  # 56 s (7.1%); ci7: 73 s
    "tests/matrices/test_sensor_matrix_rows_4.py",  # 67 s (8.6%); ci7: 65 s
    "tests/commands/test_passive.py",  # 49 s (6.2%)
    "tests/matrices/test_combinations.py",  # 43 s (5.5%)
    "tests/e2e/test_live_bus.py",  # 39 s (4.9%)
    "tests/matrices/test_recorder_matrix.py",  # 36 s (4.6%)
    "tests/offline/test_judge_memory.py",  # 15 s alone (stop 38); ci7: 22 s CPU, ~56 s in CI
    "tests/kit/test_kit_batch.py",  # 9 s (1.2%); ci7: ~22 s in CI (45 loaded), a third test since
    "tests/kit/test_esp_flavour.py",  # ci7: ~28 s in CI (two builds, two played sketches)
    "tests/matrices/test_verdict_lines.py",  # 29 s alone (stop 38, not in the 788 s)
    "tests/e2e/test_first_hour.py",  # 26 s (3.3%)
    "tests/e2e/test_roundtrip_commands.py",  # 24 s (3.0%)
    "tests/e2e/test_harness_examples.py",  # 23 s (3.0%)
    "tests/capture/test_recorded_sensor_arrays.py",  # ci7: 9.4 s CPU (15.5 before its cut)
    "tests/judges/test_gaps_alike_by_place.py",  # ci7: ~21 s in CI, 4.5 s CPU alone
    "tests/capture/test_uart_bulk.py",  # 9 s alone (stop 39: hypothesis + fault captures)
    "tests/offline/test_judge.py",  # 21 s (2.6%)
    "tests/kit/test_arduino_sensor.py",  # 20 s (2.6%)
    "tests/e2e/test_case_order.py",  # 19 s (2.4%)
    "tests/reports/test_html_aside.py",  # 11 s alone (stop 39: three forked pages)
    "tests/recorder/test_capability.py",  # 11 s (1.4%)
    "tests/test_cli.py",  # 9 s (1.2%)
    "tests/reports/test_diff.py",  # 9 s (1.2%)
    "tests/e2e/test_capture_fuzz.py",  # 9 s (1.1%)
    "tests/kit/test_arduino_logger.py",  # 9 s (1.1%)
    "tests/e2e/test_verdicts_unchanged.py",  # 8 s (1.1%)
)

#: The modules that go first, in order.
FIRST: tuple[str, ...] = WAITING + LONGEST


def module_of(item: pytest.Item) -> str:
    """The module part of a test's node id (``tests/e2e/test_rack.py``)."""
    return item.nodeid.split("::", 1)[0]


def longest_first(items: Sequence[pytest.Item]) -> list[pytest.Item]:
    """``items`` with the modules of :data:`FIRST` first, in its order; within a module and
    among the other modules, the order is kept (a stable sort by rank)."""
    rank = {module: place for place, module in enumerate(FIRST)}
    return sorted(items, key=lambda item: rank.get(module_of(item), len(FIRST)))


@pytest.hookimpl(tryfirst=True)  # before pytest groups the items by their fixtures' scopes
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The longest modules first (the comment above :data:`WAITING` says why): CI's xdist
    workers take whole modules in collection order (``.ci/test``, ``--no-loadscope-reorder``)."""
    items[:] = longest_first(items)


# CI's real-time sessions (.ci/test) collect only the modules that name a marker of TIMED as
# a word (``grep -lw``, test_*.py files): collecting the whole suite to run its 62 timed
# tests cost each of those three pytest processes 4.1 s of CPU (10.4 s on a clean clone's
# cold caches), the 28 modules 1.3 s (2.8 s); two of the three run at normal priority beside
# the niced session, the third alone at the end. A timed test in a module that does not name its
# marker (one imported from elsewhere) would never run there: every session that deselects
# one fails at once instead (the niced session and the default selection deselect them all).

#: The markers whose tests .ci/test runs in sessions of their own.
TIMED = ("realtime", "quiet")
_NAMES_TIMED = re.compile(r"\b(?:" + "|".join(TIMED) + r")\b")


@cache
def names_a_timed_marker(path: Path) -> bool:
    """Whether .ci/test's grep lists ``path``: a ``test_*.py`` file naming a TIMED marker."""
    if not path.name.startswith("test_") or path.suffix != ".py":
        return False
    return bool(_NAMES_TIMED.search(path.read_text(encoding="utf-8")))


def unlisted_timed(items: Iterable[pytest.Item]) -> list[str]:
    """Node ids of the timed tests among ``items`` whose module .ci/test's real-time sessions
    would not collect."""
    return [
        item.nodeid
        for item in items
        if any(item.get_closest_marker(name) for name in TIMED)
        and not names_a_timed_marker(item.path)
    ]


def pytest_deselected(items: Sequence[pytest.Item]) -> None:
    lost = unlisted_timed(items)
    if lost:
        raise pytest.UsageError(
            "timed tests in modules that do not name their marker (.ci/test's real-time "
            "sessions collect only modules that name 'realtime' or 'quiet'; name it there): "
            + ", ".join(lost)
        )


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
