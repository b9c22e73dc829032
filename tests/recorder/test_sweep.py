"""The recorder tolerance sweep (issue 24, item 3): a played sensor made slower step by step,
one short job per step, and where the recorder under test stops coping against where the
standard says it must cope (conformance.recorder.sweep)."""

from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from importlib import resources
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import jsonschema
import pytest

from conformance.conduct import run_into
from conformance.options import UsageError, check_sweep
from conformance.recorder.faults import RECORDER_FAULTS
from conformance.recorder.played import SensorSpec
from conformance.recorder.scenario_runner import RecorderSession
from conformance.recorder.scenarios import Scenario
from conformance.recorder.sweep import (
    AFTER_BREAK,
    AFTER_RETRY,
    FIRST_TRY,
    REPLY_LIMIT_MS,
    SWEEP_KINDS,
    WAKE_LIMIT_MS,
    Sweep,
    judge_step,
    parse_kinds,
    run_sweeps,
)
from conformance.recorder_jobs import Request, Task
from conformance.reports.sweep_chart import render, section, summary_lines
from tests.support.own_time import own_time

SCHEMA = json.loads(
    (resources.files("conformance") / "schemas" / "verdicts-1.json").read_text("utf-8")
)


def sweeps_of(port: str, kinds: tuple[str, ...] = ("reply", "wake")) -> dict[str, Sweep]:
    return {s.kind.name: s for s in run_sweeps(RecorderSession(port), kinds)}


@pytest.fixture(scope="module")
def golden() -> dict[str, Sweep]:
    return sweeps_of("sim")


def test_the_limits_are_the_standards():
    assert REPLY_LIMIT_MS == 15.4  # R-7.0-10: 15.0 ms + 0.40 ms
    assert WAKE_LIMIT_MS == 100.0  # R-7.0-07 / R-7.2-03
    reply = SWEEP_KINDS["reply"]
    assert reply.steps_ms[0] == 0 and reply.steps_ms[-1] == 100
    # the limit itself is a step, so "copes at the edge" is measured, not interpolated
    assert REPLY_LIMIT_MS in [reply.effective_ms(e) for e in reply.steps_ms]
    assert SWEEP_KINDS["wake"].steps_ms[-1] == 150


def test_golden_recorder_copes_at_every_step_within_the_limit(golden):
    for sweep in golden.values():
        inside = [s for s in sweep.steps if s.effective_ms <= sweep.kind.limit_ms]
        assert inside and all(s.outcome.coped for s in inside), sweep.kind.name
        assert sweep.flag is None
        assert sweep.copes_up_to_ms is not None and sweep.copes_up_to_ms >= sweep.kind.limit_ms


def test_golden_recorder_stops_beyond_the_limit_where_its_own_timeouts_say(golden):
    """Its 20 ms first-character timeout: a reply starting at 19 ms is taken, at 24 ms not;
    its second retry 149 ms after the break: a sensor awake at 145 ms is reached, at 150 not."""
    reply, wake = golden["reply"], golden["wake"]
    assert (reply.copes_up_to_ms, reply.first_failure_ms) == (19.0, 24.0)
    assert (wake.copes_up_to_ms, wake.first_failure_ms) == (145.0, 150.0)
    how = {s.effective_ms: s.outcome.how for s in wake.steps}
    assert how[0.0] == FIRST_TRY and how[50.0] == how[100.0] == AFTER_RETRY


def test_full_sweep_on_the_golden_recorder_stays_fast():
    """Held to its own time (tests/support/own_time.py: the wall time less the time the
    thread stood waiting for a CPU), which a busy machine does not stretch."""
    with own_time() as took:
        sweeps_of("sim")
    assert took.seconds < 10.0, took


def test_short_reply_timeout_gives_up_inside_the_limit_and_is_flagged(golden):
    faulty = sweeps_of("sim://?recorder-faults=short-reply-timeout", ("reply",))["reply"]
    assert faulty.copes_up_to_ms == 9.0
    assert faulty.copes_up_to_ms < golden["reply"].copes_up_to_ms
    assert faulty.copes_up_to_ms < REPLY_LIMIT_MS
    assert faulty.flag is not None and "R-7.0-10" in faulty.flag and "14.00 ms" in faulty.flag


def test_a_recorder_without_retries_misses_a_slow_waking_sensor_and_is_flagged():
    wake = sweeps_of("sim://?recorder-faults=no-retries", ("wake",))["wake"]
    assert wake.copes_up_to_ms == 5.0  # its command after 9 ms of marking: no second try
    assert wake.flag is not None and "R-7.0-07" in wake.flag and "R-7.2-03" in wake.flag


def test_the_short_reply_timeout_fault_is_caught_by_the_window_edge_scenario():
    """The suite's sensor answering at 15.0 ms (scenario reply-at-window-edge) shows what
    the sweep shows: a recorder giving up inside the 15.40 ms limit breaks the retry rules
    and loses the data (its matrix row proves the set exactly)."""
    assert set(RECORDER_FAULTS["short-reply-timeout"].violates) >= {"R-7.2-05", "R-4.4.8-05"}


def _step(port: str, spec: SensorSpec):
    session = RecorderSession(port)
    run = session.run_scenario(
        Scenario("step", "one step", (spec,), Request(Task.MEASURE, ("0M!",)))
    )
    return session, run


def test_judge_step_says_how_the_data_came():
    session, run = _step("sim", SensorSpec("0"))
    expected = run.expected_values("0", "M")
    got = judge_step(run.events, session.is_recorder, run.output, expected)
    assert got.coped and got.how == FIRST_TRY and got.observed_reply_ms == 9.0
    session, run = _step("sim", SensorSpec("0", unheard=3))  # deaf for a whole sequence
    got = judge_step(run.events, session.is_recorder, run.output, expected)
    assert got.coped and got.how == AFTER_BREAK, got.evidence


def test_judge_step_holds_wrong_logged_values_and_missing_data_against_the_recorder():
    session, run = _step("sim", SensorSpec("0"))
    expected = run.expected_values("0", "M")
    run.output.logged["0M!"] = [v.lstrip("+") + "1" for v in run.output.logged["0M!"]]
    got = judge_step(run.events, session.is_recorder, run.output, expected)
    assert not got.coped and got.how is None and "logged" in got.evidence
    # the wire alone (no log reported): the same transcript copes
    got = judge_step(run.events, session.is_recorder, None, expected)
    assert got.coped and "wire only" in got.evidence
    # values the sensor never sent are not its data
    got = judge_step(run.events, session.is_recorder, None, ["+9.99"] * len(expected))
    assert not got.coped


def test_sweep_option_parses_and_refuses_unknown_kinds():
    assert parse_kinds("reply,wake,reply") == ("reply", "wake")
    assert parse_kinds(None) == ()
    with pytest.raises(ValueError, match="bogus"):
        parse_kinds("reply,bogus")
    check_sweep("wake")
    with pytest.raises(UsageError):
        check_sweep("slow")


def _mark_x(mark: ET.Element, ns: str) -> float:
    circle = mark.find(f"{ns}circle")
    if circle is not None:
        return float(circle.get("cx"))
    line = mark.find(f"{ns}line")  # a cross: its two strokes centre on the step
    return (float(line.get("x1")) + float(line.get("x2"))) / 2


def test_html_section_draws_one_mark_per_step_and_the_limit_line(golden):
    sweeps = [s.to_json() for s in golden.values()]
    html = render(sweeps)
    assert 'id="sdi12-sweeps"' in html
    for sweep in sweeps:
        start = html.index(f'data-kind="{sweep["kind"]}"')
        svg = html[html.rindex("<svg", 0, start + 1) : html.index("</svg>", start) + 6]
        root = ET.fromstring(svg)
        ns = "{http://www.w3.org/2000/svg}"
        marks = root.findall(f"{ns}g")
        assert len(marks) == len(sweep["steps"])
        assert sum("coped" in m.get("class", "").split() for m in marks) == sum(
            s["coped"] for s in sweep["steps"]
        )
        limit = [e for e in root.iter(f"{ns}line") if e.get("class") == "sdi12-sweep-limit"]
        assert len(limit) == 1
        # the limit line sits between the last step inside the limit and the first beyond
        limit_x = float(limit[0].get("x1"))
        xs = [_mark_x(m, ns) for m in marks]
        placed = list(zip(xs, (st["effective_ms"] for st in sweep["steps"]), strict=True))
        inside = [x for x, ms in placed if ms <= sweep["limit_ms"]]
        beyond = [x for x, ms in placed if ms > sweep["limit_ms"]]
        assert max(inside) <= limit_x < min(beyond, default=float("inf"))
    assert "FLAG" not in html


def test_html_section_shows_the_flag_and_escapes_evidence():
    faulty = sweeps_of("sim://?recorder-faults=short-reply-timeout", ("reply",))["reply"]
    data = faulty.to_json()
    data["steps"][1]["evidence"] = "<script>alert(1)</script>"
    html = render([data])
    assert "FLAG" in html and "R-7.0-10" in html
    assert "<script>" not in html and "&lt;script&gt;" in html
    assert section(SimpleNamespace(sweeps=None)) == ""  # no --sweep: no section


def test_console_gets_one_line_per_sweep(golden):
    lines = summary_lines({"sweeps": [s.to_json() for s in golden.values()]})
    assert lines == [
        "reply sweep: copes up to 19.00 ms, gives up at 24.00 ms (limit 15.40 ms)",
        "wake sweep: copes up to 145.00 ms, gives up at 150.00 ms (limit 100.00 ms)",
    ]
    assert summary_lines({}) == []


def _verdicts(data: dict[str, Any]) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in data["requirements"]}


def test_a_sweep_run_writes_valid_verdicts_and_changes_no_verdict(tmp_path: Path):
    """--sweep through the command line: verdicts.json validates with its "sweeps" block,
    report.html has the section, the console a line per sweep; without --sweep there is no
    "sweeps" key and the verdicts are the same."""
    port = "sim://?recorder-faults=short-reply-timeout"
    out = tmp_path / "swept"
    proc = subprocess.run(
        [sys.executable, "-m", "conformance.cli", "--port", port, "--role", "recorder"]
        + ["--sweep", "--report-dir", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 1, proc.stdout + proc.stderr  # NON-COMPLIANT: the fault is caught
    swept = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator(SCHEMA).validate(swept)
    assert [s["kind"] for s in swept["sweeps"]] == ["reply", "wake"]
    assert swept["sweeps"][0]["flag"] and "FLAG: " in proc.stdout
    assert "wake sweep: copes up to" in proc.stdout
    report = (out / "report.html").read_text(encoding="utf-8")
    assert 'id="sdi12-sweeps"' in report and "sdi12-sweep-limit" in report
    plain = run_into(tmp_path / "plain", port, role="recorder")
    assert "sweeps" not in plain
    assert _verdicts(plain) == _verdicts(swept)
    assert swept["summary"] == plain["summary"]
    bad = dict(swept, sweeps=[dict(swept["sweeps"][0], unit="s")])
    assert list(jsonschema.Draft202012Validator(SCHEMA).iter_errors(bad))
    # a replay of the plain run has no sweep steps to play: the sweep stops, blaming nothing
    replayed = run_sweeps(RecorderSession(f"replay:{tmp_path / 'plain'}"), ("reply",))[0]
    assert replayed.steps == [] and "sweep-reply-0ms" in (replayed.stopped or "")
    assert replayed.flag is None and replayed.copes_up_to_ms is None
    html = render([replayed.to_json()])
    assert "no step ran" in html and "Sweep stopped" in html


def test_judging_a_swept_run_again_replays_its_sweeps(tmp_path: Path):
    """``sdi12-conform judge`` repeats the recorded options, --sweep included: the steps are
    in the recording, so the sweeps come out as the live run had them."""
    from conformance.offline.judge import replay_options
    from conformance.replay.recording import read_recording

    live = run_into(tmp_path / "live", "sim", sweep="wake", role="recorder")
    options = replay_options(read_recording(tmp_path / "live" / "transcript.jsonl"), _judge_args())
    assert options.sweep == "wake"
    again = run_into(
        tmp_path / "again",
        f"replay:{tmp_path / 'live'}",
        sweep="wake",
        role="recorder",
    )
    assert again["sweeps"] == live["sweeps"] and live["sweeps"][0]["copes_up_to_ms"] == 145.0


def _judge_args() -> Any:
    return SimpleNamespace(sdi_version=None, strict=False, report_dir=None)
