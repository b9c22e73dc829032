"""A recorder that never finishes a job (issue 20, "Harness edges"): its job is cut at a stated
budget of bus time, the rules over every transmission judge what it sent until then, and the
rules about that job cannot PASS on a job that never ended. Also: the recorder harness's stderr
is in every report, and an operator at the interactive prompt can say "cannot"."""

from __future__ import annotations

import io
import os
import shlex
import sys

import pytest

from conformance.conduct import run_once
from conformance.recorder.drivers import Interactive
from conformance.recorder.job_time import JobBudget, JobLink, JobTimeout, job_budget
from conformance.recorder.played import build_sensors
from conformance.recorder.scenarios import LONG_TTT, SCENARIOS
from conformance.recorder_jobs import Request, Task
from conformance.sim.bus import SimBus, SimLink
from tests.support.paths import ROOT

HARNESS = ROOT / "examples" / "python" / "recorder_harness.py"
FAULT = "waits-forever-for-service-request"
#: Rules over every transmission of the run: they judge the cut job's transmissions in full.
WHOLE_RUN = ("R-7.0-02", "R-7.0-06", "R-7.0-17", "R-4.2-01", "R-7.0-13")


def _verdicts(data: dict) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in data["requirements"]}


def _budget(name: str, override: float | None = None) -> JobBudget:
    scenario = SCENARIOS[name]
    return job_budget(scenario.request, build_sensors(scenario.sensors), override)


def test_the_budget_is_stated_from_the_commands_and_the_played_ttt():
    assert _budget("no-service-request").seconds == 30 + 10 + 2  # aM!, ttt 2 s
    assert _budget("ttt-over-255").seconds == 30 + 10 + LONG_TTT
    assert _budget("basic-commands").seconds == 30 + 10 * 6  # no measurement: no ttt
    assert "2 s of the ttt" in _budget("no-service-request").note()
    assert _budget("ttt-over-255", 12.0) == JobBudget(12.0, "--job-timeout")


def test_the_job_link_cuts_a_wait_at_the_budget_and_not_before():
    link = SimLink(SimBus([]))
    job = JobLink(link, JobBudget(5.0, "test"))  # type: ignore[arg-type]
    assert job.receive(4.0) == [] and link.now() == pytest.approx(4.0)  # inside: as it was
    with pytest.raises(JobTimeout, match="within its 5 s of bus time"):
        job.receive(60.0)
    assert link.now() == pytest.approx(5.0)  # it waited up to the cut, not to 60 s
    with pytest.raises(JobTimeout):
        job.write(b"\x30")  # nothing goes out after the cut


def test_a_recorder_that_waits_forever_is_cut_and_judged_on_what_it_sent():
    data = run_once(f"sim://?recorder-faults={FAULT}", role="recorder")
    verdicts = _verdicts(data)
    assert verdicts["R-4.4.5-05"] == "FAIL"  # no aD0! once ttt ran out
    for rid in WHOLE_RUN:  # before the cut counted, every one of these was INCONCLUSIVE
        assert verdicts[rid] == "PASS", rid
    # the rule about the job itself: no PASS on a job that never ended, saying why
    found = next(r for r in data["requirements"] if r["id"] == "R-4.4.5-04")
    assert found["verdict"] == "INCONCLUSIVE"
    assert "within its 42 s of bus time" in " ".join(f["detail"] for f in found["findings"])


def _details(data: dict, rid: str) -> str:
    return " ".join(
        f["detail"] for r in data["requirements"] if r["id"] == rid for f in r["findings"]
    )


def test_the_waits_forever_fail_gives_the_wait_and_leaves_the_collection_undecided():
    """The FAIL says how long past ttt no aD0! came; whether the values would then have been
    collected (R-4.4.8-05) the cut leaves unobserved: it FAILed 'stopped after the reply'."""
    data = run_once(f"sim://?recorder-faults={FAULT}", role="recorder")
    assert "s from when ttt ran out to the tool cutting the job" in _details(data, "R-4.4.5-05")
    assert _verdicts(data)["R-4.4.8-05"] == "INCONCLUSIVE"
    assert "the recorder still in this measurement" in _details(data, "R-4.4.8-05")


def test_a_clean_recorder_cut_by_a_short_budget_fails_nothing():
    """--job-timeout shorter than the jobs: every scenario is cut while the golden recorder is
    still in it, so what it had not sent by then proves nothing. Before, six rules FAILed on
    those absences ('never sent', 'stopped at D0', 'not on the wire as typed')."""
    data = run_once("sim", role="recorder", job_timeout=1.5)
    verdicts = _verdicts(data)
    assert [r for r, v in verdicts.items() if v == "FAIL"] == []
    assert verdicts["R-4.4-02"] == "INCONCLUSIVE"
    assert "not sent before the tool cut a job at its budget" in _details(data, "R-4.4-02")
    for rid in ("R-4.4.7-08", "R-5.1-04", "R-5.2-08", "R-5.4-01", "R-4.4.14-02"):
        assert verdicts[rid] == "INCONCLUSIVE", rid


def test_a_harness_that_loops_forever_is_cut_and_its_stderr_kept(tmp_path):
    """The same fault behind ``exec:``: the harness plans waits for ever, the tool cuts it at
    ``--job-timeout``, and what the harness logged about it is in the report."""
    port = f"exec:{shlex.quote(sys.executable)} {HARNESS} {FAULT}"
    data = run_once(port, job_timeout=20.0, role="recorder")
    verdicts = _verdicts(data)
    assert verdicts["R-4.4.5-05"] == "FAIL"
    for rid in WHOLE_RUN:
        assert verdicts[rid] == "PASS", rid
    detail = " ".join(
        f["detail"] for r in data["requirements"] if r["id"] == "R-4.4.5-04" for f in r["findings"]
    )
    assert "within its 20 s of bus time (--job-timeout)" in detail
    stderr = data["run"]["link"]["harness_stderr"]
    assert "[no-service-request]" in stderr and "job ended by the tool" in stderr


def test_the_golden_harness_has_an_empty_stderr_key():
    port = f"exec:{shlex.quote(sys.executable)} {HARNESS}"
    data = run_once(port, keyword="test_every_basic_command_and_family", role="recorder")
    assert data["run"]["link"]["harness_stderr"] == ""
    assert (
        "harness_stderr"
        not in run_once("sim", keyword="test_every_basic_command_and_family", role="recorder")[
            "run"
        ]["link"]
    )


def test_an_operator_can_say_cannot_at_the_prompt():
    request = Request(Task.CONCURRENT, ("0C!", "1C!"))
    read_fd, write_fd = os.pipe()
    with os.fdopen(read_fd) as answers, os.fdopen(write_fd, "w") as operator:
        shown = io.StringIO()
        driver = Interactive(timeout=2.0, prompt_out=shown, answer_in=answers)
        operator.write("cannot this logger measures one sensor at a time\n")
        operator.flush()
        out = driver.act("concurrent-two", request, None)  # type: ignore[arg-type]
        assert out.cannot == "this logger measures one sensor at a time"
        assert "'cannot WHY'" in shown.getvalue()
        operator.write("Cannot\n")  # no reason given: still a cannot, with no words
        operator.flush()
        assert driver.act("concurrent-two", request, None).cannot == ""  # type: ignore[arg-type]
        operator.write("logged both; cannot say more\n")  # a note, not a cannot
        operator.flush()
        out = driver.act("concurrent-two", request, None)  # type: ignore[arg-type]
        assert out.cannot is None and out.notes == ["logged both; cannot say more"]
