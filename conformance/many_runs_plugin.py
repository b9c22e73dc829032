"""The session's side of :mod:`conformance.many_runs`: a pytest plugin (named with ``-p`` by
:func:`~conformance.many_runs.judged_in_one_session`) whose run-test loop calls the batch's
work and judges, as runs of their own, the runs the work conducts (that module's docstring
says how a run is reset and ended)."""

from __future__ import annotations

import traceback
from contextlib import AbstractContextManager, nullcontext
from copy import deepcopy
from dataclasses import replace
from types import TracebackType

import pytest

from . import many_runs, plugin
from .conduct import RunResult
from .interrupts import GUARD
from .report_folder import run_folder
from .run import ConformanceRun, RunOptions, given_options


@pytest.hookimpl(tryfirst=True)
def pytest_runtestloop(session: pytest.Session) -> bool | None:
    config = session.config
    batch = next(
        (p for p in config.pluginmanager.get_plugins() if isinstance(p, many_runs.Batch)), None
    )
    given = given_options(config)
    if batch is None or given is None:
        return None  # not a batch's session
    if session.testsfailed or config.option.collectonly:
        return None  # pytest's own loop says why; the work runs with sessions of its own
    selection = deepcopy(plugin.run_of(config).selection)
    plugin.release_report_folder(config)
    plugin.detach_run(config)  # the template run: never run, the items' records dropped
    if any(item.get_closest_marker(m) for item in session.items for m in many_runs.SKIPPING_MARKS):
        return True  # not judged here (many_runs.BATCH_BLOCKED): the work runs as it is
    batch.run(ManyRuns(session, given.options, selection))
    return True


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo) -> pytest.TestReport:
    """The report as every other plugin makes it (this wrapper is the outermost), then the
    case's exception let go (:func:`_let_go`): the report holds what it says of it already.

    Kept, the exception is a cycle (the frame that caught it, pytest's
    ``CallInfo.from_call``, holds it; its traceback holds that frame), and that frame holds
    the frames that called it (``f_back``) up to this batch's ``judge``, whose ``run`` holds
    the run's link, session and every event: a matrix row's FAIL held its whole run so,
    ~10^5 objects a row that the collector walked as survivors while the batch lasted and
    freed only at a full collection (issue 22, :func:`conformance.gc_pace.one_row`). Let
    go, the run is freed by its counts when its fixtures are torn down. ``call.excinfo`` is
    read after this hook only by ``pytest_exception_interact`` (the debugger's, whose plugin
    a judged run never loads, and faulthandler's, which cancels a timeout the suite never
    sets)."""
    report = yield
    if call.excinfo is not None:
        _let_go(call.excinfo.tb)
        call.excinfo = None
    return report


def _let_go(tb: TracebackType | None) -> None:
    """Each frame of ``tb`` cleared (``traceback.clear_frames``: the one that caught the
    exception no longer holds it) and its ``f_locals`` read again: on Python 3.11 a frame
    keeps the dict of its locals the last reading made (pytest reads each frame's for
    ``__tracebackhide__`` as it makes the report), which clearing leaves as it was; read
    again, it loses what was cleared."""
    traceback.clear_frames(tb)
    while tb is not None:
        tb.tb_frame.f_locals  # noqa: B018 (the reading is the point)
        tb = tb.tb_next


class ManyRuns:
    """The session judging runs while its batch's work lasts (a
    :class:`conformance.many_runs.Server`)."""

    def __init__(self, session: pytest.Session, template: RunOptions, selection: object) -> None:
        self.session = session
        self.template = template
        self.selection = selection  # what the collection kept and left out

    def idle(self) -> bool:
        return plugin.RUN not in self.session.config.stash

    def judge(self, options: RunOptions, files: tuple[str, ...] | None) -> RunResult:
        """One run in this session, as :func:`conformance.conduct.conduct` would make it in
        a session of its own with ``html=False`` and nothing printed."""
        session = self.session
        config = session.config
        report_dir = run_folder(options.report_dir, options.role)
        options = replace(options, report_dir=str(report_dir))
        run = ConformanceRun(options)
        run.report_files = files
        run.selection = deepcopy(self.selection)  # type: ignore[assignment]
        config.stash[plugin.RUN] = run
        try:
            try:
                plugin.check_reports_writable(config)
            except pytest.UsageError:  # as a session's collection stops: no case, no verdict
                return RunResult(int(pytest.ExitCode.USAGE_ERROR), report_dir, run)
            if GUARD.requested:  # Ctrl-C between two runs: the batch stops here
                raise KeyboardInterrupt
            GUARD.reset()  # the last run's end closed it
            plugin.give_case_records(config, session.items)
            code = _run_items(session)
            plugin.finish_run(session, code)
            session._setupstate.teardown_exact(None)  # after a pytest.exit: as pytest's end
            return RunResult(code, report_dir, run)
        finally:
            plugin.release_report_folder(config)
            plugin.detach_run(config)


def _run_items(session: pytest.Session) -> int:
    """pytest's run-test loop over the session's items and the exit status pytest's session
    would have ended with, the run's warnings caught as its cases' are (:func:`_warnings`)."""
    config = session.config
    caught = config.pluginmanager.get_plugin("warnings")
    with _warnings(config, caught):
        return _run_protocols(session, caught)


def _warnings(config: pytest.Config, caught: object | None) -> AbstractContextManager[None]:
    """pytest's warnings plugin's catch around each case (its filters: the suite's
    ``filterwarnings``, ``-W``, pytest's deprecations as errors, each warning recorded to
    ``pytest_warning_recorded``) taken once around a whole run: the same filters over the
    same cases (no case carries a ``filterwarnings`` mark, and nothing of the suite changes
    a filter), a warning recorded with the run's empty node id rather than its case's
    (recorded to no reader: a batch's session has no terminal and no report files), and
    ~2 hook calls and a ``warnings.catch_warnings`` less a case. None if the plugin is
    blocked (nothing caught, as in a session without it)."""
    if caught is None:
        return nullcontext()
    from _pytest.warnings import catch_warnings_for_item

    return catch_warnings_for_item(config, config.hook, when="runtest", item=None)


def _run_protocols(session: pytest.Session, caught: object | None) -> int:
    """The loop of :func:`_run_items`, each item's runtest protocol run by every plugin but
    the warnings plugin (``caught``: caught around the run instead)."""
    session.testsfailed = 0
    session.shouldstop = session.shouldfail = False
    items = session.items
    hook = session.config.pluginmanager.subset_hook_caller(
        "pytest_runtest_protocol", [caught] if caught is not None else []
    )
    try:
        for i, item in enumerate(items):
            nextitem = items[i + 1] if i + 1 < len(items) else None
            hook(item=item, nextitem=nextitem)
            if session.shouldfail:
                raise session.Failed(session.shouldfail)
            if session.shouldstop:
                raise session.Interrupted(session.shouldstop)
    except session.Failed:
        return int(pytest.ExitCode.TESTS_FAILED)
    except (session.Interrupted, pytest.exit.Exception) as exc:
        _forget_request(items[i])  # the item the exit came out of
        excinfo = pytest.ExceptionInfo.from_exception(exc)
        session.config.hook.pytest_keyboard_interrupt(excinfo=excinfo)
        returncode = getattr(exc, "returncode", None)
        return int(pytest.ExitCode.INTERRUPTED if returncode is None else returncode)
    if session.testsfailed:
        return int(pytest.ExitCode.TESTS_FAILED)
    return int(pytest.ExitCode.OK if items else pytest.ExitCode.NO_TESTS_COLLECTED)


def _forget_request(item: pytest.Item) -> None:
    """What pytest's runtest protocol does at its end, which a ``pytest.exit`` inside it
    skipped: the item's request and fixture values let go. Kept, the cut-short run's request
    went on serving the item in the next run (its fixtures the old run's): a version-1.3 run
    after a run stopped by "no device answered" ordered its measurements otherwise and left
    R-4.4.12-01 unjudged (tests/test_many_runs.py)."""
    if hasattr(item, "_request"):
        item._request = False  # type: ignore[attr-defined]
        item.funcargs = None  # type: ignore[attr-defined]
