"""What a recorder logged, checked against what the played sensors sent (issue 20): the judge
(count, order, sign, digits, decimal point, HB at its type's precision), the harness's ``log``
lines, and the ``--trigger`` log file (CSV, JSON lines, malformed)."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest

from conformance.harness import protocol as proto
from conformance.harness.channel import HarnessError
from conformance.harness.client import log_lines
from conformance.harness.protocol import HarnessProtocolError
from conformance.judges.recorder.logged import (
    NOTHING_REPORTED,
    LogReport,
    Sent,
    compare,
    judge_logged_values,
)
from conformance.protocol.binary import DataType
from conformance.recorder.drivers import Trigger
from conformance.recorder.logfile import LogFileError, parse_log, read_log_file
from conformance.recorder.replay_driver import OUTPUT_NOTE, RecordedRecorder, output_note
from conformance.recorder.scenario_runner import RecorderSession
from conformance.recorder_jobs import RecorderOutput, Request, Task
from conformance.sim.bus import SimBus, SimLink
from conformance.transcript import Event, EventKind
from conformance.verdicts import Verdict

M2 = [
    "+1234.567",
    "-12.34567",
    "+0.000123",
    "-999.9999",
    "+5555.555",
    "-0.100001",
    "+76543.21",
    "-1.234567",
    "+99.99999",
]


@pytest.fixture(scope="module")
def golden() -> RecorderSession:
    """The golden recorder on the simulated bus; scenarios run once for the module."""
    return RecorderSession("sim")


def judged(session: RecorderSession, logs: dict[str, dict[str, list[str]] | None], **kw):
    """The logged-values findings for the scenarios named in ``logs`` with those reports."""
    names = list(logs)
    for name in names:
        session.run(name)
    reports = [LogReport(n, logs[n]) for n in names]
    found = judge_logged_values(session.view(*names), reports, session.uncertainty, **kw)
    return {f.requirement: f for f in found}, found


def test_the_golden_recorder_logs_what_the_sensors_sent(golden):
    names = ["d0-to-d2", "concurrent-99", "families", "high-volume-binary", "empty-data"]
    by_id, _ = judged(golden, {n: golden.run(n).output.logged for n in names})
    assert by_id["R-4.4-02"].verdict is Verdict.PASS, by_id["R-4.4-02"].detail
    assert by_id["R-5.4-01"].verdict is Verdict.PASS
    assert golden.run("d0-to-d2").output.logged == {"0M2!": M2}


@pytest.mark.parametrize(
    ("logged", "words"),
    [
        (
            [v.lstrip("+-") for v in M2],
            "value 2 logged as 12.34567, the sensor sent -12.34567: "
            "its sign lost (4 of 9 values wrong)",
        ),
        (
            [v[:7] for v in M2],
            "value 1 logged as +1234.5, the sensor sent +1234.567: digits cut off",
        ),
        (M2[:-1], "logged 8 value(s), the sensor sent 9: the last 1 missing, from +99.99999 on"),
        ([*M2, "+1"], "logged 10 value(s), the sensor sent 9: 1 extra, from +1 on"),
        ([M2[1], M2[0], *M2[2:]], "values logged in another order: value 1 is -12.34567"),
        (
            ["+1234,567", *M2[1:]],
            "value 1 logged as +1234,567, the sensor sent +1234.567: not a number",
        ),
        (["+12345.67", *M2[1:]], "other digits or decimal point"),
        ([], "logged 0 value(s), the sensor sent 9"),
    ],
)
def test_a_wrong_log_fails_with_what_is_wrong(golden, logged, words):
    by_id, _ = judged(golden, {"d0-to-d2": {"0M2!": logged}})
    finding = by_id["R-4.4-02"]
    assert finding.verdict is Verdict.FAIL
    assert words in finding.detail
    assert finding.evidence[0] == "d0-to-d2: 0M2!"


def test_values_are_compared_as_numbers(golden):
    """A '+' dropped, zeros added or exponent notation is the same number: no FAIL."""
    same = ["1234.567", "-12.345670", "1.23e-4", "-999.9999", "5555.555", "-.100001",
            "76543.21", "-1.234567", "00099.99999"]  # fmt: skip
    by_id, _ = judged(golden, {"d0-to-d2": {"0M2!": same}})
    assert by_id["R-4.4-02"].verdict is Verdict.PASS, by_id["R-4.4-02"].detail


def test_hb_values_are_compared_at_their_type_precision():
    pi32 = Sent("3.140000104904175", DataType.FLOAT32)
    assert pi32.matches("3.14") and pi32.matches("3.1400001")
    assert not pi32.matches("3.1") and not pi32.matches("-3.14")
    e64 = Sent("2.718281828459045", DataType.FLOAT64)
    assert e64.matches("2.718281828459045") and not e64.matches("2.7182817")
    big = Sent("-2147483648", DataType.INT32)
    assert big.matches("-2147483648") and not big.matches("2147483648")
    assert compare([big], ["-214748"]) == (
        "value 1 logged as -214748, the sensor sent -2147483648: digits cut off"
    )


def test_no_report_is_not_applicable_never_a_pass(golden):
    by_id, found = judged(golden, {"d0-to-d2": None, "families": None})
    assert {f.verdict for f in found} == {Verdict.NA}
    assert by_id["R-4.4-02"].detail == by_id["R-5.4-01"].detail == NOTHING_REPORTED


def test_a_measurement_left_out_of_the_log_fails(golden):
    """Once the recorder reports what it logged, a measurement on the wire missing from the
    report (or a scenario without any report) is values lost."""
    logs = {"d0-to-d2": {"0M2!": M2}, "two-sensors": {"0M!": ["+22.15", "+1013.2", "+45.7"]},
            "concurrent-two": None}  # fmt: skip
    by_id, _ = judged(golden, logs)
    detail = by_id["R-4.4-02"].detail
    assert by_id["R-4.4-02"].verdict is Verdict.FAIL
    assert "two-sensors: 1M!: the sensor sent 3 value(s), none logged" in detail
    assert "concurrent-two: 0C!: the sensor sent 5 value(s), none logged (no log report" in detail


def test_a_scenario_cut_short_without_a_report_is_not_held_against_the_recorder(golden):
    """A trigger that failed or timed out had no chance to write its log: no FAIL for it."""
    for name in ("d0-to-d2", "two-sensors"):
        golden.run(name)
    reports = [LogReport("d0-to-d2", {"0M2!": M2}), LogReport("two-sensors", None, None, True)]
    found = judge_logged_values(golden.view("d0-to-d2", "two-sensors"), reports, 0.0)
    by_id = {f.requirement: f for f in found}
    assert by_id["R-4.4-02"].verdict is Verdict.PASS, by_id["R-4.4-02"].detail
    assert "two-sensors" not in by_id["R-4.4-02"].detail


def test_values_logged_for_a_command_never_sent_fail(golden):
    by_id, _ = judged(golden, {"d0-to-d2": {"0M2!": M2, "0M7!": ["+1.0"]}})
    assert by_id["R-4.4-02"].verdict is Verdict.FAIL
    assert "d0-to-d2: 0M7!: 1 value(s) logged, the command never sent" in by_id["R-4.4-02"].detail


def test_an_unreadable_report_is_inconclusive_naming_why(golden):
    golden.run("d0-to-d2")
    reports = [LogReport("d0-to-d2", {}, "SDI12_LOG_FILE line 2: not JSON")]
    found = judge_logged_values(golden.view("d0-to-d2"), reports, golden.uncertainty)
    unreadable = [f for f in found if f.verdict is Verdict.INCONCLUSIVE and f.observed]
    assert [f.requirement for f in unreadable] == ["R-4.4-02"]
    assert "line 2: not JSON" in unreadable[0].detail
    assert Verdict.PASS not in {f.verdict for f in found}


def test_a_v13_recorder_leaves_the_high_volume_rule_not_applicable(golden):
    by_id, _ = judged(golden, {"d0-to-d2": {"0M2!": M2}}, high_volume=False)
    assert by_id["R-5.4-01"].verdict is Verdict.NA
    assert by_id["R-4.4-02"].verdict is Verdict.PASS


# -- the harness's log lines -------------------------------------------------------------------
def test_log_lines_parse():
    assert proto.parse_log("log 0M! +1.5 -2") == proto.LogLine("0M!", ("+1.5", "-2"))
    assert proto.parse_log("log 0M!") == proto.LogLine("0M!", ())
    assert proto.is_log("log 0M! 1") and not proto.is_log("logged 0M! 1")


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("log", "takes a command"),
        ("log 0M +1", "not wire text"),
        ("log 0M!! +1", "not wire text"),
        ("log 0M! +1  +2", "separated by one space"),
    ],
)
def test_malformed_log_lines_are_protocol_errors(text, reason):
    with pytest.raises(HarnessProtocolError, match=reason):
        proto.parse_log(text)


def test_long_measurements_take_several_log_lines_within_the_line_limit():
    values = [f"+{i}.125" for i in range(99)]
    lines = log_lines("0C9!", values)
    assert len(lines) > 1 and all(len(line) <= proto.MAX_LINE for line in lines)
    assert [v for line in lines for v in line.split()[2:]] == values


def _log_harness(tmp_path: Path, lines: list[str]) -> str:
    """A recorder harness that sends nothing, writes ``lines`` and then ``done``."""
    script = tmp_path / "logging-recorder.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import sys
            sys.stdin.readline()
            print("hello 1 logging-recorder", flush=True)
            if sys.stdin.readline().startswith("job"):
                for line in {lines!r} + ["done"]:
                    print(line)
                sys.stdout.flush()
                sys.stdin.readline()
            """
        )
    )
    return f"exec:{sys.executable} {script}"


def test_a_harness_reports_what_it_logged_with_log_lines(tmp_path):
    port = _log_harness(tmp_path, ["log 0M! +22.15 +1013.2", "log 0M! +45.7", "log 1M!"])
    out = RecorderSession(port).run("service-request").output
    assert out.logged == {"0M!": ["+22.15", "+1013.2", "+45.7"], "1M!": []}
    assert out.reported_logged() == out.logged
    assert out.log_source == "3 log line(s) from the harness"


def test_a_harness_without_log_lines_reports_nothing(tmp_path):
    out = RecorderSession(_log_harness(tmp_path, [])).run("service-request").output
    assert out.reported_logged() is None


def test_a_malformed_log_line_stops_the_run_naming_it(tmp_path):
    session = RecorderSession(_log_harness(tmp_path, ["log 0M +1"]))
    with pytest.raises(HarnessError, match=r"protocol error: log command '0M'.*'log 0M \+1'"):
        session.run("service-request")


# -- the trigger's log file --------------------------------------------------------------------
def test_csv_and_json_lines_logs_parse():
    csv_text = "# the logger's export\n0M!,+22.15, +1013.2\n\n0M!,+45.7\n1M!\n"
    assert parse_log(csv_text) == {"0M!": ["+22.15", "+1013.2", "+45.7"], "1M!": []}
    json_text = '{"command": "0M!", "values": ["+22.15", 1013.20], "t": 5}\n' + (
        '{"command": "0M!", "values": [45]}\n'
    )
    assert parse_log(json_text) == {"0M!": ["+22.15", "1013.20", "45"]}
    assert parse_log("") == {}


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ('{"command": "0M!", "values": ["+1"]}\n{"command": "0M!"', "line 2: not JSON"),
        ('{"command": "0M!", "values": [true]}', "line 1: 'values' is not a list"),
        ('{"command": "0M!", "value": ["+1"]}', "line 1: wants an object with 'command'"),
        ('{"command": 5, "values": []}', "line 1: the command '5' is not wire text"),
        ("command,values\n0M!,+1", "line 1: the command 'command' is not wire text"),
        ("0M!,+1,,+2", "line 1: an empty value"),
        ('0M!,"+1', "line 1: not CSV"),
    ],
)
def test_a_malformed_log_file_names_the_line(text, words):
    with pytest.raises(LogFileError, match=words):
        parse_log(text)


def test_no_log_file_is_no_report(tmp_path):
    assert read_log_file(tmp_path / "absent.log") is None


REQUEST = Request(Task.MEASURE, ("0M!",))


@pytest.mark.parametrize(
    ("script", "logged", "problem"),
    [
        (
            "printf '0M!,+22.15,+1013.2\\n' > \"$SDI12_LOG_FILE\"",
            {"0M!": ["+22.15", "+1013.2"]},
            None,
        ),
        (
            'echo \'{"command": "0M!", "values": ["-1"]}\' > "$SDI12_LOG_FILE"',
            {"0M!": ["-1"]},
            None,
        ),
        (': > "$SDI12_LOG_FILE"', {}, None),
        ("true", None, None),
        ('echo \'{"command": "0M!"\' > "$SDI12_LOG_FILE"', None, "SDI12_LOG_FILE line 1: not JSON"),
    ],
)
def test_the_trigger_reads_the_log_file_the_logger_wrote(script, logged, problem):
    out = Trigger(script, 10).act("service-request", REQUEST, link=None)  # type: ignore[arg-type]
    assert out.reported_logged() == logged
    if problem is None:
        assert out.log_problem is None
    else:
        assert out.log_problem is not None and problem in out.log_problem


def test_the_trigger_gives_each_scenario_a_fresh_log_file():
    trigger = Trigger('test ! -e "$SDI12_LOG_FILE" && echo 0M!,+1 > "$SDI12_LOG_FILE"', 10)
    for scenario in ("service-request", "two-sensors"):
        out = trigger.act(scenario, REQUEST, link=None)  # type: ignore[arg-type]
        assert out.logged == {"0M!": ["+1"]}


def test_the_log_report_survives_a_replay():
    """The recorder-output note keeps where the log came from and why it was unreadable."""
    out = RecorderOutput(log_source="SDI12_LOG_FILE (0 command(s))", log_problem="line 1: x")
    note = output_note("service-request", out, None)
    assert note.startswith(OUTPUT_NOTE)
    events = [
        Event(EventKind.NOTE, "tool", 0.0, 0.0, text="scenario service-request: ..."),
        Event(EventKind.NOTE, "tool", 1.0, 1.0, text=note),
    ]
    again = RecordedRecorder(events).act("service-request", REQUEST, SimLink(SimBus([])))
    assert again.log_source == out.log_source and again.log_problem == out.log_problem
    assert again.reported_logged() == {}


def silent_logger():
    """A recorder program (``sim://?recorder=``) that does the golden job but reports nothing
    of what it logged, as a harness without ``log`` lines does."""
    from conformance.recorder.golden import GoldenRecorder

    def program(request: Request, link) -> RecorderOutput:  # noqa: ANN001 - a Link
        out = GoldenRecorder()(request, link)
        out.logged = {}
        return out

    return program


def test_a_run_whose_recorder_reports_nothing_leaves_the_check_not_applicable():
    from conformance.conduct import run_once

    port = f"sim://?recorder={__name__}:silent_logger"
    data = run_once(port, keyword="logged", role="recorder")
    found = {r["id"]: r for r in data["requirements"]}
    for rid in ("R-4.4-02", "R-5.4-01"):
        assert found[rid]["verdict"] == "N/A", found[rid]
        assert found[rid]["findings"][0]["detail"] == NOTHING_REPORTED


def test_a_harness_flooding_log_lines_is_stopped(tmp_path):
    session = RecorderSession(_log_harness(tmp_path, ["log 0M! +1"] * (proto.MAX_LOG_LINES + 1)))
    with pytest.raises(HarnessError, match="more than 1000 log lines in one job"):
        session.run("service-request")


def test_a_measurement_never_collected_is_not_logged_as_sent_r_4_4_02():
    """R3 IoT's Zephyr SDI-12 master (twenty-seventh round, docs/kit.md) parses the ``atttn``
    reply to ``aMC!`` as if it carried a CRC, rejects the valid ``00023``, asks for no data
    and logs nothing: "logged as sent" PASSed R-4.4-02 on it, the sensor having "sent" no
    values only because none were asked for (a logger that drops every measurement after its
    reply PASSed R-4.4-02 so). Nothing logged for a measurement never collected is not an
    observation; values logged for one are still a FAIL, and a measurement of no values
    (``a0000``) logged empty is still one."""
    from tests.judges.recorder.test_recorder_judges import Wire, by_id

    dropped = Wire().brk().rec("0MC!").sensor("00023\r\n").view()
    nothing = by_id(judge_logged_values(dropped, [LogReport("p", {"0MC!": []})], 0.0))
    assert nothing["R-4.4-02"].verdict is Verdict.INCONCLUSIVE, nothing["R-4.4-02"].detail
    made_up = by_id(judge_logged_values(dropped, [LogReport("p", {"0MC!": ["+1.5"]})], 0.0))
    assert made_up["R-4.4-02"].verdict is Verdict.FAIL
    empty = Wire().brk().rec("0M!").sensor("00000\r\n").view()
    none_due = by_id(judge_logged_values(empty, [LogReport("p", {"0M!": []})], 0.0))
    assert none_due["R-4.4-02"].verdict is Verdict.PASS
