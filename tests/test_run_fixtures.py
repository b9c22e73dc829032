"""conformance.plugin.RunFixtures: ``sdi12_run`` and ``case`` without ``request`` (issue 22).
Each case gets its own record and the run's, asked for in its setup or while it runs; a case
without ``@requirements`` is refused by name; and no lookup makes pytest's per-request
fixture definition (the cost the cut removes)."""

from __future__ import annotations

import pytest
from _pytest import fixtures

from conformance.conduct import conduct
from conformance.run import RunOptions

CASES = """
import pytest
from conformance.verdicts import Finding, Verdict


@pytest.mark.requirements("R-4.4.12-01")
def test_first(sensor, case, sdi12_run):
    assert case.record is sdi12_run.cases[-1]
    case.add(Finding("R-4.4.12-01", Verdict.PASS, "first", test=case.record.nodeid))


@pytest.mark.requirements("R-4.4.12-02", "R-4.4.12-03")
def test_second(request, sdi12_run):
    case = request.getfixturevalue("case")  # while the case runs, not in its setup
    assert case.requirements == ("R-4.4.12-02", "R-4.4.12-03")
    case.add(Finding("R-4.4.12-02", Verdict.PASS, "second", test=case.record.nodeid))
    case.add(Finding("R-4.4.12-03", Verdict.PASS, "second", test=case.record.nodeid))


def test_unmarked(case):
    pass
"""


class Reports:
    """Keeps the setup and call reports of the cases."""

    def __init__(self) -> None:
        self.found: dict[tuple[str, str], pytest.TestReport] = {}

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        self.found[(report.nodeid.rsplit("::", 1)[-1], report.when)] = report


def test_each_case_gets_its_own_record_and_no_request_definition(pytester, monkeypatch):
    made: list[object] = []
    real = fixtures.RequestFixtureDef.__init__

    def counted(self, request):  # noqa: ANN001, ANN202 - pytest's own signature
        made.append(request)
        real(self, request)

    monkeypatch.setattr(fixtures.RequestFixtureDef, "__init__", counted)
    pytester.makepyfile(fakecases_of_run_fixtures=CASES)
    pytester.syspathinsert()
    reports = Reports()
    folder = pytester.path / "run"
    result = conduct(
        RunOptions(port="sim", report_dir=str(folder)),
        cases="fakecases_of_run_fixtures",
        html=False,
        rootdir=pytester.path,
        plugins=[reports],
        files=(),
    )
    assert result.run is not None
    records = {r.name: r for r in result.run.cases}
    assert sorted(records) == ["test_first", "test_second"]
    assert records["test_first"].requirements == ("R-4.4.12-01",)
    assert records["test_first"].nodeid.endswith("::test_first")
    assert [f.requirement for f in records["test_second"].findings] == [
        "R-4.4.12-02",
        "R-4.4.12-03",
    ]
    assert all("second" in f.detail for f in records["test_second"].findings)
    assert not reports.found[("test_first", "call")].failed  # run to its end
    assert not reports.found[("test_second", "call")].failed
    unmarked = reports.found[("test_unmarked", "setup")]
    assert unmarked.failed and "test_unmarked uses `case` without @requirements" in str(
        unmarked.longrepr
    )
    # only test_second's own `request` argument makes one: none for sdi12_run or case
    assert len(made) == 1
