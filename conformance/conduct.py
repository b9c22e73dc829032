"""One conformance run in this process: the entry point every caller shares.

The main command, ``judge`` (replay and passive), the fault matrices and the capture round
trip all build a :class:`~conformance.run.RunOptions` and call :func:`conduct`; the options
reach the plugin as the object they are (no flags written out and parsed back), and the
verdicts come back from memory (no verdicts.json read back, no subprocess).
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from .exits import exit_code
from .report_folder import run_folder
from .run import ConformanceRun, GivenOptions, RunOptions
from .suite import suite_args


@dataclass(frozen=True)
class RunResult:
    """What one run gave: pytest's status, its folder, and the run the plugin made (None when
    pytest stopped before the plugin could make one, e.g. a usage error)."""

    pytest_code: int
    report_dir: Path
    run: ConformanceRun | None

    @property
    def document(self) -> dict[str, Any] | None:
        """verdicts.json as it was written (None: the run wrote none)."""
        return self.run.document if self.run is not None else None

    @property
    def exit_code(self) -> int | None:
        """The run's exit status (None: no verdicts to give one from)."""
        document = self.document
        return None if document is None else exit_code(document, self.pytest_code)


def conduct(
    options: RunOptions,
    *,
    cases: str | None = None,
    html: bool = True,
    terminal: bool = False,
    verbose: bool = False,
    rootdir: Path | str | None = None,
    plugins: Sequence[object] = (),
    files: tuple[str, ...] | None = None,
    html_aside: bool = False,
) -> RunResult:
    """Run the conformance cases ``cases`` (default: the role's, ``testcases.<role>``) with
    ``options`` in this process.

    ``html`` writes report.html and junit.xml beside verdicts.json; ``terminal`` keeps
    pytest's own output (``verbose`` adds -v); ``plugins`` are more pytest plugins (the
    console's live progress). The run's folder is made here when the options name none.
    ``files``: only these of the run's report files (``reports.writers.REPORT_WRITERS``
    names; None: all); without verdicts.json the document is None and the verdicts are read
    from ``RunResult.run`` (:meth:`~conformance.run.ConformanceRun.verdict_lines`).
    ``html_aside``: the caller owns this process to its end (the main command), so report.html
    may be rendered by a forked process beside the rest (:mod:`conformance.reports.html_aside`).
    """
    import pytest

    from .many_runs import serving

    shared = serving(options, cases, html, terminal or verbose, tuple(plugins), html_aside)
    if shared is not None:  # a batch of runs judged in one pytest session (many_runs)
        return shared.judge(options, files)
    report_dir = run_folder(options.report_dir, options.role)
    options = replace(options, report_dir=str(report_dir))
    argv = suite_args(
        cases or f"testcases.{options.role}",
        report_dir,
        rootdir=rootdir,
        html=html,
        terminal=terminal or verbose,
    )
    if options.keyword:
        argv += ["-k", options.keyword]
    if verbose:
        argv.append("-v")
    given = GivenOptions(options)
    given.files = files
    given.html_aside = html_aside
    code = int(pytest.main(argv, plugins=[*plugins, given]))
    # pytest's objects hold ``given`` in reference cycles: the run is the caller's alone from
    # here, freed when the caller lets it go (plugin.detach_run)
    run, given.run = given.run, None
    return RunResult(code, report_dir, run)


class NoVerdicts(RuntimeError):
    """The run wrote no verdicts (pytest stopped first: nothing collected, a usage error)."""


def run_once(port: str, role: str = "sensor", **options: Any) -> dict:
    """Run the ``role`` suite in this process against ``port``; return verdicts.json.
    ``options``: more :class:`~conformance.run.RunOptions` fields (``version="1.3"``,
    ``keyword="crc"``)."""
    with tempfile.TemporaryDirectory(prefix=f"sdi12-{role}-") as tmp:
        return run_into(Path(tmp), port, role, **options)


def run_into(report_dir: Path, port: str, role: str = "sensor", **options: Any) -> dict:
    """Run the ``role`` suite in this process against ``port`` with its reports (no HTML) in
    ``report_dir``; return verdicts.json (from memory: the run's own, never a file's)."""
    report_dir.mkdir(parents=True, exist_ok=True)
    given = RunOptions(port=port, role=role, report_dir=str(report_dir), **options)
    result = conduct(given, html=False, rootdir=report_dir)
    if result.document is None:
        raise NoVerdicts(
            f"the {role} suite against {port} wrote no verdicts (pytest exit {result.pytest_code})"
        )
    return result.document
