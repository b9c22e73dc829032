"""Every file a finished run writes into its folder, in one table.

python-can keeps its log formats in one table (``can.io.MESSAGE_WRITERS``: a suffix -> the
writer class), so a new format is one entry and nothing that writes logs changes. The same
here: :data:`REPORT_WRITERS` names each file the plugin writes when the run ends, in the order
written, and :func:`write_reports` is the only caller. A new report format is a function
``(run, folder) -> Path`` and its row here. Files written before verdicts.json are pinned by
its manifest (``reports/manifest.PINNED`` says which); the rows after it are renderings of it.

report.html and junit.xml are not in the table: pytest's own plugins (pytest-html, filled by
:class:`~conformance.reports.html.HtmlReportPlugin`, and ``--junitxml``) write them after the
session ends, from the same run, when :func:`conformance.suite.suite_args` asks for them
(:data:`PYTEST_RENDERINGS`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..run import ConformanceRun
from . import verdicts_json


@dataclass(frozen=True)
class ReportWriter:
    """One file of a run's folder: its name, what it holds, and the function writing it."""

    file: str
    holds: str
    write: Callable[[ConformanceRun, Path], Path]


REPORT_WRITERS: tuple[ReportWriter, ...] = (
    ReportWriter(
        "transcript.jsonl",
        "every break and character of the run, stamped (the evidence; `judge` reads it)",
        verdicts_json.write_transcript,
    ),
    ReportWriter(
        "verdicts.json",
        "the verdict per requirement with findings (contract sdi12-conform/verdicts/1)",
        verdicts_json.write,
    ),
)

#: The files pytest's own plugins render from the same run once the session ends.
PYTEST_RENDERINGS: dict[str, str] = {
    "report.html": "pytest-html, self-contained (reports/html.py fills it)",
    "junit.xml": "pytest --junitxml, xunit2: one test case per conformance case",
}


def write_reports(run: ConformanceRun, directory: Path) -> list[Path]:
    """Write every file of :data:`REPORT_WRITERS` into ``directory``, in order (only those
    ``run.report_files`` names, when the caller of the run named some)."""
    only = run.report_files
    return [w.write(run, directory) for w in REPORT_WRITERS if only is None or w.file in only]
