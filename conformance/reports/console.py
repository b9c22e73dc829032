"""The console side of a run: live progress while cases run, then a summary from verdicts.json.

Uses rich on a terminal and plain lines otherwise (CI logs, pipes).
"""

from __future__ import annotations

from typing import Any

import pytest
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

STYLE = {
    "PASS": "green",
    "FAIL": "bold red",
    "WARN": "yellow",
    "INCONCLUSIVE": "magenta",
    "N/A": "dim",
    "ERROR": "bold white on red",
    "COMPLIANT": "bold white on green",
    "NON-COMPLIANT": "bold white on red",
    "INCOMPLETE": "bold black on yellow",
}


class ProgressPlugin:
    """pytest plugin showing which case runs (a bus run can take minutes)."""

    def __init__(self, console: Console) -> None:
        self.console = console
        self.progress: Progress | None = None
        self.task: Any = None
        self.done = 0
        self.total = 0

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        self.total = len(session.items)
        if self.console.is_terminal:
            self.progress = Progress(
                TextColumn("[bold]judging"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                TextColumn("{task.description}"),
                console=self.console,
                transient=True,
            )
            self.progress.start()
            self.task = self.progress.add_task("", total=self.total)
        else:
            self.console.print(f"running {self.total} conformance cases")

    def pytest_runtest_logstart(self, nodeid: str, location: Any) -> None:
        if self.progress is not None:
            self.progress.update(self.task, description=nodeid.split("::")[-1])

    def pytest_runtest_logfinish(self, nodeid: str, location: Any) -> None:
        self.done += 1
        if self.progress is not None:
            self.progress.update(self.task, completed=self.done)

    def pytest_sessionfinish(self, session: pytest.Session) -> None:
        if self.progress is not None:
            self.progress.stop()


def print_summary(console: Console, data: dict[str, Any], report_dir: str) -> None:
    summary = data["summary"]
    verdict = summary["verdict"]
    dut = data["dut"]
    reqs = data["requirements"]
    judged = [r for r in reqs if r["testable"]]
    console.print()
    ident = dut.get("identification") or "(no identification)"
    console.print(
        f"DUT {dut.get('address')!s} · SDI-12 {dut.get('sdi12_version')} · {ident.strip()!r}",
        markup=False,
        highlight=False,
    )
    console.print(
        f"role {data['run']['role']} · port {data['run']['port']} · "
        f"link {data['run']['link']['kind']}",
        markup=False,
        highlight=False,
    )
    table = Table(title="Requirements", show_edge=False)
    for name in summary["counts"]:
        table.add_column(name, justify="right", style=STYLE.get(name, ""))
    table.add_row(*(str(n) for n in summary["counts"].values()))
    console.print(table)
    untestable = len(reqs) - len(judged)
    console.print(
        f"{len(judged)} testable requirements judged, {untestable} untestable here "
        f"(electrical, inspection or the other role)",
        highlight=False,
    )
    bad = [r for r in reqs if r["verdict"] in ("FAIL", "ERROR", "INCONCLUSIVE", "WARN")]
    if bad:
        lines = Table(show_header=True, show_edge=False, title="Findings to read")
        lines.add_column("verdict")
        lines.add_column("requirement")
        lines.add_column("reason", overflow="fold")
        for r in sorted(
            bad, key=lambda r: ("ERROR", "FAIL", "INCONCLUSIVE", "WARN").index(r["verdict"])
        ):
            reason = next((f["detail"] for f in r["findings"] if f["verdict"] == r["verdict"]), "")
            lines.add_row(
                f"[{STYLE[r['verdict']]}]{r['verdict']}[/]", r["id"], reason.replace("[", "\\[")
            )
        console.print(lines)
    if data["run"].get("stop_reason"):
        console.print(f"stopped: {data['run']['stop_reason']}", markup=False)
    console.print(f"[{STYLE.get(verdict, '')}] {verdict} [/]  report: {report_dir}/report.html")
