"""How the conformance suite is invoked: one place that builds pytest's arguments.

The CLI, the fault matrices and the benchmark all run the same suite; they differ only in
which outputs they want, so none of them spells the pytest command line on its own.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: the folder that holds the ``testcases`` package (a checkout or site-packages)
SUITE_ROOT = Path(str(resources.files("testcases"))).parent

#: pytest's default plugins that nothing of a judged run uses, blocked: no case takes their
#: fixtures (tmp_path, monkeypatch, recwarn, caplog, subtests), nothing logs, no run is
#: debugged, stepped, paste-binned, set up only or made of doctests or unittest classes, and
#: no plugin of the run reads a legacy ``py.path``. Each still registered options and
#: fixtures, imported its modules (pdb and readline for ``debugging``, unittest) and, for
#: ``logging``, wrapped every phase of every case in log capturing: 0.9% of a sim process's
#: instructions together. ``assertion``: no case and no plugin of the run uses a bare assert
#: (a case records findings), yet rewriting the case modules cost ~0.1 s of CPU in every run
#: that could not cache it; blocked, nothing installs the rewriting hook (``--assert`` stays
#: plain) and nothing wraps each case. ``capture``: the cases print nothing, and fd capture
#: swallowed every repaint of the live progress bar (it stood at "collecting the cases" for a
#: whole run); blocked, nothing is captured, as ``--capture=no`` did, and its early readline
#: import and per-phase hooks are gone. ``warnings``, ``threadexception`` and
#: ``faulthandler`` stay: they decide what becomes of a warning, a thread's exception or a
#: crash.
UNUSED_PYTEST_PLUGINS = (
    "debugging", "doctest", "legacypath", "tmpdir", "monkeypatch", "recwarn", "pastebin",
    "stepwise", "setuponly", "setupplan", "subtests", "logging", "unittest", "assertion",
    "capture",
)  # fmt: skip


def suite_args(
    cases: str,
    report_dir: Path | str,
    *,
    rootdir: Path | str | None = None,
    html: bool = True,
    terminal: bool = False,
) -> list[str]:
    """pytest arguments for the conformance cases ``cases`` (``testcases.sensor``), their
    HTML and JUnit reports into ``report_dir``. The run's own options are not among them:
    :func:`conformance.conduct.conduct` hands them to the plugin whole.

    The bundled ``suite.ini`` keeps a project's own pytest settings out of the judged run.
    ``html`` adds report.html and junit.xml; ``terminal`` keeps pytest's own output.
    ``rootdir`` defaults to the folder holding the ``testcases`` package, so test IDs and
    JUnit classnames (``testcases.sensor.test_4_4_12_crc``) do not depend on where the tool
    runs or is installed.
    """
    report_dir = Path(report_dir)
    if rootdir is None:
        rootdir = SUITE_ROOT
    args = [
        "-c", str(resources.files("conformance") / "suite.ini"),
        "--rootdir", str(rootdir),
        # only the plugins the judged run needs, named: none of the environment's (xdist,
        # pytest-benchmark, hypothesis's own...) is imported or can change the run, and
        # finding and loading them all cost about 0.1 s of each run
        "--disable-plugin-autoload",
        # no conftest.py either: pytest otherwise loads the one in the working folder and in
        # each of its ``test*`` folders (a project's tests/conftest.py, with its hooks,
        # fixtures and the plugins it names) into the judged run, which then depends on
        # where the tool was started; the suite has none of its own. ~5 ms of each run
        # started from a checkout (tests/test_conduct.py)
        "--noconftest",
        "-p", "conformance.plugin",
        "-p", "no:cacheprovider",
        "-p", "no:unraisableexception",  # its gc passes at the end cost ~0.3 s a run
        # pytest's own plugins a judged run never uses (:data:`UNUSED_PYTEST_PLUGINS`)
        *[arg for name in UNUSED_PYTEST_PLUGINS for arg in ("-p", f"no:{name}")],
        "--pyargs", cases,
    ]  # fmt: skip
    if html:
        args += [
            "-p", "pytest_metadata.plugin", "-p", "pytest_html.plugin",
            f"--html={report_dir / 'report.html'}", "--self-contained-html",
            f"--junitxml={report_dir / 'junit.xml'}", "-o", "junit_family=xunit2",
        ]  # fmt: skip
    if not terminal:
        args += ["-p", "no:terminal"]
    return args
