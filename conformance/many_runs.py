"""Many conformance runs judged in one pytest session (issue 22: a fault matrix's rows).

A run started by :func:`conformance.conduct.conduct` is a pytest session of its own: pytest's
configuration and plugins, the fixture manager, the collection of the role's cases, then the
cases, then the session's end. A fault-matrix row makes two (the live run and its capture's
replay), and the fixed part was ~130 ms of a ~900 ms row. :func:`judged_in_one_session` pays
it once for a whole batch of runs: it starts one pytest session over the role's cases and,
in place of pytest's run-test loop, calls the caller's ``work``; every ``conduct`` made
meanwhile whose selection is the session's is judged in it as a run of its own:

- a fresh :class:`~conformance.run.ConformanceRun` with the run's options, its selection the
  one the session's collection made (the same cases, -k, --req, profile and bus: anything
  else is judged in a session of its own, as before), fresh case records on the items;
- the run's report folder taken and let go, the Ctrl-C guard opened and closed, the
  session's failure counts cleared, as a session's start and end do;
- the items' runtest protocol in pytest's order; the last item tears the session fixtures
  (``sdi12_run``, ``sensor``, ``recorder``) down, so the next run makes its own;
- a ``pytest.exit`` (:meth:`ConformanceRun.cut_short`) ends only that run: its exit status is
  the run's, its reports are written, then its fixtures torn down, in the order pytest's own
  session end takes (the plugin's ``pytest_sessionfinish`` first, the runner's teardown
  after);
- the run finished and its reports written as the plugin's session end does
  (:func:`conformance.plugin.finish_run`), the run detached from pytest's objects.

The verdicts and reports are the fresh session's (``tests/test_many_runs.py`` compares every
verdict, finding and detail of live, cut-short and replayed runs both ways).
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from copy import deepcopy
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, TypeVar

import pytest

from . import plugin
from .interrupts import GUARD
from .options import UsageError, check_values
from .ports import PortError
from .preflight import check_role_options
from .report_folder import run_folder
from .run import ConformanceRun, GivenOptions, RunOptions
from .suite import suite_args

if TYPE_CHECKING:
    from .conduct import RunResult

T = TypeVar("T")

#: the session serving runs at this moment (None: every run is a session of its own)
_SERVING: ManyRuns[Any] | None = None


def selection_key(options: RunOptions) -> tuple[Any, ...]:
    """What decides which cases a run collects and keeps (plugin.keep_*_cases, -k)."""
    return (
        options.role,
        options.bus,
        options.profile,
        tuple(options.requirements),
        options.keyword,
    )


class ManyRuns(Generic[T]):
    """A pytest plugin object: its run-test loop calls ``work`` and judges the runs ``work``
    asks for (:meth:`judge`) while it lasts."""

    def __init__(self, template: RunOptions, work: Callable[[], T]) -> None:
        self.template = template
        self.work = work
        self.session: pytest.Session | None = None
        self.selection: Any = None
        self.started = False  # work was called (in the session)
        self.result: T | None = None
        self.error: BaseException | None = None

    def serves(
        self,
        options: RunOptions,
        cases: str | None,
        html: bool,
        terminal: bool,
        plugins: tuple[object, ...],
        html_aside: bool,
    ) -> bool:
        """Whether a run asked for with these arguments is one this session can judge as
        a session of its own would: the same cases kept, no report page, no output, no
        other plugin, options the plugin's configure takes (a refusal, or a declaration to
        read, is left to a session of its own: its errors are that session's)."""
        return (
            self.session is not None
            and plugin.RUN not in self.session.config.stash  # not inside another run
            and cases in (None, f"testcases.{options.role}")
            and not (html or terminal or plugins or html_aside)
            and options.declaration is None
            and selection_key(options) == selection_key(self.template)
            and _usable(options)
        )

    @pytest.hookimpl(tryfirst=True)
    def pytest_runtestloop(self, session: pytest.Session) -> bool | None:
        if session.testsfailed or session.config.option.collectonly:
            return None  # pytest's own loop says why; the work runs with sessions of its own
        config = session.config
        self.selection = deepcopy(plugin.run_of(config).selection)
        plugin.release_report_folder(config)
        plugin.detach_run(config)  # the template run: never run, the items' records dropped
        global _SERVING
        previous, _SERVING = _SERVING, self
        self.session, self.started = session, True
        try:
            self.result = self.work()
        except BaseException as exc:  # the caller's to see, not pytest's to report
            self.error = exc
        finally:
            _SERVING, self.session = previous, None
        return True

    def judge(self, options: RunOptions, files: tuple[str, ...] | None) -> RunResult:
        """One run in this session, as :func:`conformance.conduct.conduct` would make it in
        a session of its own with ``html=False`` and nothing printed."""
        from .conduct import RunResult

        session = self.session
        assert session is not None
        config = session.config
        report_dir = run_folder(options.report_dir, options.role)
        options = replace(options, report_dir=str(report_dir))
        run = ConformanceRun(options)
        run.report_files = files
        run.selection = deepcopy(self.selection)
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
            code = self._run_items(session)
            plugin.finish_run(session, code)
            session._setupstate.teardown_exact(None)  # after a pytest.exit: as pytest's end
            return RunResult(code, report_dir, run)
        finally:
            plugin.release_report_folder(config)
            plugin.detach_run(config)

    @staticmethod
    def _run_items(session: pytest.Session) -> int:
        """pytest's run-test loop over the session's items and the exit status pytest's
        session would have ended with."""
        session.testsfailed = 0
        session.shouldstop = session.shouldfail = False
        items = session.items
        try:
            for i, item in enumerate(items):
                nextitem = items[i + 1] if i + 1 < len(items) else None
                item.config.hook.pytest_runtest_protocol(item=item, nextitem=nextitem)
                if session.shouldfail:
                    raise session.Failed(session.shouldfail)
                if session.shouldstop:
                    raise session.Interrupted(session.shouldstop)
        except session.Failed:
            return int(pytest.ExitCode.TESTS_FAILED)
        except (session.Interrupted, pytest.exit.Exception) as exc:
            excinfo = pytest.ExceptionInfo.from_exception(exc)
            session.config.hook.pytest_keyboard_interrupt(excinfo=excinfo)
            returncode = getattr(exc, "returncode", None)
            return int(pytest.ExitCode.INTERRUPTED if returncode is None else returncode)
        if session.testsfailed:
            return int(pytest.ExitCode.TESTS_FAILED)
        return int(pytest.ExitCode.OK if items else pytest.ExitCode.NO_TESTS_COLLECTED)


def _usable(options: RunOptions) -> bool:
    """Whether the plugin's configure takes ``options`` (its checks, as it makes them)."""
    try:
        check_values(vars(options), plugin=True)
        check_role_options(
            options.role, options.trigger, options.address, options.sweep, options.job_timeout
        )
    except (UsageError, PortError):
        return False
    return True


def serving(
    options: RunOptions,
    cases: str | None,
    html: bool,
    terminal: bool,
    plugins: tuple[object, ...],
    html_aside: bool,
) -> ManyRuns[Any] | None:
    """The session that will judge this run, if one is serving and can."""
    found = _SERVING
    if found is not None and found.serves(options, cases, html, terminal, plugins, html_aside):
        return found
    return None


def judged_in_one_session(work: Callable[[], T], role: str = "sensor") -> T:
    """``work()``, the ``role`` runs it conducts judged in one pytest session (the module's
    docstring). Inside a session already serving, or if the session cannot collect the
    cases, ``work`` runs as it is (each run a session of its own)."""
    if _SERVING is not None:
        return work()
    with tempfile.TemporaryDirectory(prefix=f"sdi12-{role}-runs-") as tmp:
        template = RunOptions(port="sim", role=role, report_dir=tmp)
        many = ManyRuns(template, work)
        given = GivenOptions(template)
        given.files = ()
        pytest.main(suite_args(f"testcases.{role}", Path(tmp), html=False), plugins=[many, given])
    if many.error is not None:
        raise many.error
    if not many.started:
        return work()
    return many.result  # type: ignore[return-value]
