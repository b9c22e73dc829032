"""A FAIL or WARN rests on what it names (issue 18), like a PASS (issue 10): at least one
observation counted and one evidence line, enforced where a finding is built
(:class:`conformance.verdicts.Finding`); these tests prove the rule on the finding and walk
the verdicts of faulty runs, whose FAILs and WARNs must all carry their observations.
"""

from __future__ import annotations

import pytest

from conformance.conduct import run_once
from conformance.emulator import FAULTS
from conformance.recorder.faults import RECORDER_FAULTS
from conformance.verdicts import NOTHING_UNDER_IT, Finding, Verdict, failed, warned

LINE = "t=1.2345 s: 0! -> '(silence)'"


@pytest.mark.parametrize("verdict", [Verdict.FAIL, Verdict.WARN])
@pytest.mark.parametrize(
    ("observed", "evidence", "missing"),
    [
        (0, [], "no observation counted and no evidence line"),
        (0, [LINE], "no observation counted"),
        (2, [], "no evidence line"),
    ],
)
def test_a_fail_or_warn_with_nothing_under_it_is_inconclusive(verdict, observed, evidence, missing):
    f = Finding("R-4.4.1-01", verdict, "no reply", observed=observed, evidence=evidence)
    assert f.verdict is Verdict.INCONCLUSIVE
    assert f.detail == f"{NOTHING_UNDER_IT} ({missing}): would be {verdict}: no reply"


def test_a_fail_or_warn_that_names_its_observation_stands():
    assert failed("R-4.4.1-01", "x", observed=1, evidence=[LINE]).verdict is Verdict.FAIL
    assert warned("R-4.4.1-01", "x", observed=1, evidence=[LINE]).verdict is Verdict.WARN
    # a SHOULD rule's FAIL is capped at WARN, and needs its evidence just the same
    assert failed("R-4.4.4-02", "x", observed=1, evidence=[LINE]).verdict is Verdict.WARN
    assert failed("R-4.4.4-02", "x", observed=1).verdict is Verdict.INCONCLUSIVE
    # the helpers leave other verdicts alone
    assert Finding("R-4.4.1-01", Verdict.NA, "n/a").verdict is Verdict.NA


def _bad_findings(data: dict) -> list[tuple[str, dict]]:
    return [
        (r["id"], f)
        for r in data["requirements"]
        for f in r["findings"]
        if f["verdict"] in ("FAIL", "WARN") or f["detail"].startswith(NOTHING_UNDER_IT)
    ]


#: faults whose FAILs/WARNs came with nothing under them before issue 18: a silence, a
#: changed buffer, a refused address change, an aborted concurrent measurement, a short break
SENSOR_FAULTS = (
    "ignores-short-breaks",
    "buffer-cleared-after-read",
    "address-change-not-applied",
    "break-aborts-concurrent",
    "undefined-measure-silent",
)


@pytest.mark.parametrize(
    ("port", "role", "declared"),
    [(f"sim://?faults={f}", "sensor", FAULTS[f].violates) for f in SENSOR_FAULTS]
    + [
        (f"sim://?recorder-faults={f}", "recorder", RECORDER_FAULTS[f].violates)
        for f in ("no-retries", "addresses-0-4-only")
    ],
)
def test_every_fail_and_warn_of_a_faulty_run_names_its_observations(port, role, declared):
    data = run_once(port, role=role)
    bad = _bad_findings(data)
    assert {rid for rid, f in bad if f["verdict"] in ("FAIL", "WARN")} >= set(declared)
    for rid, f in bad:
        assert not f["detail"].startswith(NOTHING_UNDER_IT), (rid, f["detail"])
        assert f["observed"] >= 1, (rid, f)
        assert f["evidence"] and all(line.strip() for line in f["evidence"]), (rid, f)
