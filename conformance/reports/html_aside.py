"""report.html rendered by a second process while this one writes the run's other files.

A whole ``sdi12-conform --port sim`` process used one core of two from start to end (issue
22: its wall time is the target). What the HTML report needs is settled once the run has
finished (its cases, findings and transcript, all in memory), and nothing else the run writes
or prints reads the HTML: so at that point the process forks, the child renders report.html
(each case's findings, timing diagram and wire excerpt, then pytest-html's page: about a tenth
of the process's CPU) and ends, while the parent writes transcript.jsonl, verdicts.json and
junit.xml and prints the summary. The parent waits for the child where pytest-html would have
written the page, so the file is complete before the run returns, and writes it itself if the
child did not (it failed, or was killed): the page is never lost, only made in another place.

Only in a process the tool owns to its end (``conduct(..., html_aside=True)``: the main
command's own process), on Linux, with no other thread (a fork copies only the calling thread;
a real-time link's reader thread would be missing in the child), and only when pytest-html is
writing a page. Anywhere else the report is rendered in the process as before.
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable
from typing import Any, Protocol


class SummaryHook(Protocol):
    """What :class:`Aside` asks of the conformance plugin's HTML hooks
    (:class:`~conformance.reports.html.HtmlReportPlugin`)."""

    aside: Aside | None

    def pytest_html_results_summary(
        self, prefix: list[str], summary: list[str], postfix: list[str], session: Any
    ) -> None: ...


def can_fork() -> bool:
    """Whether this process may fork a renderer: Linux (fork is the default start method
    there and copies nothing it should not), no thread but this one."""
    alone = threading.active_count() == 1
    return sys.platform.startswith("linux") and hasattr(os, "fork") and alone


def pytest_html_page(plugins: list[Any]) -> Any | None:
    """pytest-html's report object among the session's plugins (None: no page is written)."""
    try:
        from pytest_html.basereport import BaseReport
    except ImportError:
        return None
    return next((p for p in plugins if isinstance(p, BaseReport)), None)


class Aside:
    """The child rendering report.html, as the parent sees it."""

    def __init__(self, pid: int, page: Any, ours: SummaryHook) -> None:
        self.pid = pid
        self.ours = ours
        self._render: Callable[..., None] = page._generate_report
        #: what pytest-html handed our summary hook in the parent (for writing it here)
        self.summary_lists: tuple[list[str], list[str], list[str]] | None = None
        self.wrote: bool | None = None  # None: not waited for yet

    def wait(self) -> bool:
        """Wait for the child (once); whether it wrote the page."""
        if self.wrote is None:
            try:
                _, status = os.waitpid(self.pid, 0)
                self.wrote = os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0
            except ChildProcessError:  # reaped elsewhere: its outcome is unknown
                self.wrote = False
        return self.wrote

    def generate(self, *args: Any, **kwargs: Any) -> None:
        """Stands for pytest-html's ``_generate_report`` in the parent: the child's page, or
        the page made here when the child did not write it."""
        if self.wait():
            return
        self.ours.aside = None
        if self.summary_lists is not None:
            prefix, summary, postfix = self.summary_lists
            self.ours.pytest_html_results_summary(prefix, summary, postfix, session=None)
        self._render(*args, **kwargs)


def render_aside(session: Any, ours: SummaryHook) -> Aside | None:
    """Fork a child that writes report.html through pytest-html's own session end and exits;
    in the parent, pytest-html's rendering then waits for it (:meth:`Aside.generate`). None:
    no fork (no page to write, or :func:`can_fork` says no)."""
    page = pytest_html_page(session.config.pluginmanager.get_plugins())
    if page is None or not can_fork():
        return None
    aside = Aside(os.fork(), page, ours)
    if aside.pid == 0:  # the child: the page, and nothing else (no atexit, no flush)
        code = 1
        try:
            page.pytest_sessionfinish(session)
            code = 0
        finally:
            os._exit(code)
    page._generate_report = aside.generate
    ours.aside = aside
    return aside
