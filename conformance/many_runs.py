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

This module is the run layer's side (the entry point, the session serving at the moment,
which runs it may serve); the session's side is the pytest plugin
:mod:`conformance.many_runs_plugin`, named to pytest by ``-p``. The verdicts and reports
are the fresh session's (``tests/test_many_runs.py`` compares every
verdict, finding and detail of live, cut-short and replayed runs both ways).
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, Generic, Protocol, TypeVar

from .options import UsageError, check_values
from .ports import PortError
from .preflight import check_role_options
from .run import GivenOptions, RunOptions
from .suite import suite_args

T = TypeVar("T")

#: pytest's plugins a batch's session blocks beyond the suite's own
#: (:data:`conformance.suite.UNUSED_PYTEST_PLUGINS`): ``skipping`` acts only on a case
#: marked ``skip``, ``skipif`` or ``xfail`` or calling ``pytest.xfail``, which no case of the
#: suite is (a session whose cases carry such a mark judges no run: each is a session of its
#: own, :func:`conformance.many_runs_plugin.pytest_runtestloop`); kept, it evaluated those
#: marks and wrapped each phase of each case (~3 hook calls a case, 62 cases a run). A run
#: of one's own (the CLI, ``pytest --pyargs testcases``) keeps it.
BATCH_BLOCKED = ("skipping",)

#: the marks ``skipping`` acts on: a case carrying one is judged in a session of its own
SKIPPING_MARKS = ("skip", "skipif", "xfail")


class Server(Protocol):
    """The session judging runs (:class:`conformance.many_runs_plugin.ManyRuns`)."""

    template: RunOptions

    def judge(self, options: RunOptions, files: tuple[str, ...] | None) -> Any:
        """The run, as :func:`conformance.conduct.conduct` returns it."""

    def idle(self) -> bool:
        """Whether no run is being judged at this moment."""


#: the session serving runs at this moment (None: every run is a session of its own)
_SERVING: Server | None = None


class Batch(Generic[T]):
    """A pytest plugin object naming the work of a session that judges many runs: the
    session's plugin (``many_runs_plugin``) calls ``work`` in place of pytest's run-test loop
    and keeps what it returned or raised here."""

    def __init__(self, work: Callable[[], T]) -> None:
        self.work = work
        self.started = False  # work was called (in the session)
        self.result: T | None = None
        self.error: BaseException | None = None

    def run(self, server: Server) -> None:
        """``work()`` with ``server`` judging the runs it conducts."""
        global _SERVING
        previous, _SERVING = _SERVING, server
        self.started = True
        try:
            self.result = self.work()
        except BaseException as exc:  # the caller's to see, not pytest's to report
            self.error = exc
        finally:
            _SERVING = previous


def selection_key(options: RunOptions) -> tuple[Any, ...]:
    """What decides which cases a run collects and keeps (plugin.keep_*_cases, -k)."""
    return (
        options.role,
        options.bus,
        options.profile,
        tuple(options.requirements),
        options.keyword,
    )


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
) -> Server | None:
    """The session that will judge this run, if one is serving and can judge it as a
    session of its own would: the same cases kept, no report page, no output, no other
    plugin, options the plugin's configure takes (a refusal, or a declaration to read, is
    left to a session of its own: its errors are that session's)."""
    found = _SERVING
    if (
        found is not None
        and found.idle()  # not inside another run
        and cases in (None, f"testcases.{options.role}")
        and not (html or terminal or plugins or html_aside)
        and options.declaration is None
        and selection_key(options) == selection_key(found.template)
        and _usable(options)
    ):
        return found
    return None


def judged_in_one_session(work: Callable[[], T], role: str = "sensor") -> T:
    """``work()``, the ``role`` runs it conducts judged in one pytest session (the module's
    docstring). Inside a session already serving, or if the session cannot collect the
    cases, ``work`` runs as it is (each run a session of its own)."""
    import pytest

    if _SERVING is not None:
        return work()
    batch = Batch(work)
    with tempfile.TemporaryDirectory(prefix=f"sdi12-{role}-runs-") as tmp:
        given = GivenOptions(RunOptions(port="sim", role=role, report_dir=tmp))
        given.files = ()
        args = suite_args(f"testcases.{role}", Path(tmp), html=False)
        blocked = [arg for name in BATCH_BLOCKED for arg in ("-p", f"no:{name}")]
        pytest.main([*args, *blocked, "-p", "conformance.many_runs_plugin"], plugins=[batch, given])
    if batch.error is not None:
        raise batch.error
    if not batch.started:
        return work()
    return batch.result  # type: ignore[return-value]
