"""What a batch's pytest session (``conformance.many_runs``, a fault matrix's rows) leaves out
of each case's protocol, and that the runs it judges are the runs judged alone: pytest's
skipping plugin is blocked (a session whose cases carry a skip/xfail mark judges no run),
the warnings plugin's catch is taken once around a run, with the same filters, rather than
around each case. A run of one's own keeps both plugins as they were."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from conformance import many_runs, plugin
from conformance.conduct import conduct
from conformance.matrices.sensor_matrix import fault_port
from conformance.run import RunOptions
from conformance.suite import suite_args
from tests.support.steady_verdicts import steady


class Warned:
    """A pytest plugin keeping the warnings a session records for its cases."""

    def __init__(self) -> None:
        self.messages: list[str] = []

    def pytest_warning_recorded(self, warning_message: warnings.WarningMessage, when: str) -> None:
        if when == "runtest":
            self.messages.append(str(warning_message.message))


def warning_case_of(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every case's ``case`` fixture warns (a DeprecationWarning, which pytest's catch shows
    each time), from inside the case's protocol."""
    inner = plugin.case_of

    def warned(node: pytest.Item, run: object):  # type: ignore[no-untyped-def]
        warnings.warn(f"deprecated in {node.name}", DeprecationWarning, stacklevel=1)
        return inner(node, run)  # type: ignore[arg-type]

    monkeypatch.setattr(plugin, "case_of", warned)


def judged(folder: Path, port: str, warned: Warned | None) -> tuple[int, object, list[str]]:
    """A matrix row's run of ``port`` (no HTML, no files), the warnings of its cases kept by
    ``warned`` (None: a batch's session, whose plugin set the run may not add to)."""
    folder.mkdir(parents=True)
    options = RunOptions(port=port, report_dir=str(folder))
    if warned is None:
        server = many_runs.serving(options, None, False, False, (), False)
        assert server is not None
        warned = Warned()
        manager = server.session.config.pluginmanager  # type: ignore[attr-defined]
        manager.register(warned)
        try:
            result = conduct(options, html=False, rootdir=folder, files=())
        finally:
            manager.unregister(warned)
    else:
        result = conduct(options, html=False, rootdir=folder, files=(), plugins=(warned,))
    assert result.run is not None
    return result.pytest_code, steady(result.run.verdict_lines()), sorted(warned.messages)


def test_a_batch_blocks_skipping_and_catches_warnings_around_each_run():
    seen: list[tuple[bool, bool]] = []

    def work() -> None:
        server = many_runs._SERVING
        assert server is not None
        manager = server.session.config.pluginmanager  # type: ignore[attr-defined]
        seen.append((manager.is_blocked("skipping"), manager.is_blocked("warnings")))

    many_runs.judged_in_one_session(work)
    assert seen == [(True, False)]
    own = suite_args("testcases.sensor", "reports", html=False)
    assert "no:skipping" not in own and "no:warnings" not in own  # a run of one's own


@pytest.mark.parametrize("fault", ["never-standby", "wrong-crc"])
def test_a_failing_rows_verdicts_and_warnings_equal_a_run_of_its_own(tmp_path, monkeypatch, fault):
    warning_case_of(monkeypatch)
    port = fault_port((fault, (), "14", ()))
    alone = judged(tmp_path / "alone", port, Warned())
    together = many_runs.judged_in_one_session(lambda: judged(tmp_path / "together", port, None))
    assert together == alone
    assert alone[0] == int(pytest.ExitCode.TESTS_FAILED)  # a FAIL row, as the fault declares
    assert len(alone[2]) > 10 and len(set(alone[2])) == len(alone[2])  # one a case, each kept


def test_a_session_whose_cases_carry_a_skipping_mark_judges_no_run(tmp_path, monkeypatch):
    # every case carries "requirements": taken as a skipping mark, the batch must step aside
    monkeypatch.setattr(many_runs, "SKIPPING_MARKS", ("requirements",))
    served: list[bool] = []

    def run() -> tuple[int, object]:
        folder = tmp_path / "run"
        folder.mkdir()
        options = RunOptions(port="sim", report_dir=str(folder))
        served.append(many_runs.serving(options, None, False, False, (), False) is not None)
        result = conduct(options, html=False, rootdir=folder, files=())
        assert result.run is not None
        return result.pytest_code, steady(result.run.verdict_lines())

    code, lines = many_runs.judged_in_one_session(run)
    assert served == [False]  # a session of its own, which skipping is part of
    assert code == int(pytest.ExitCode.OK) and lines
