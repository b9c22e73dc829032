"""Every subcommand as careful as the main one (issue 19): a hint leads somewhere the
subcommand accepts, a mistyped name gets "did you mean", the help shows what there is, and a
bad value is a usage error (exit 4), never an internal one (exit 3)."""

from __future__ import annotations

import json

import pytest

from conformance.cli import SUBCOMMAND_HELP, main
from conformance.monitor.command import heard_as_asked
from conformance.recorder.faults import RECORDER_FAULTS


def run(capsys, *argv: str) -> tuple[int, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def test_a_mistyped_subcommand_is_offered_the_subcommands(capsys):
    code, text = run(capsys, "jugde", "reports/x")
    assert code == 4
    assert "did you mean judge?" in text and "unrecognized arguments" not in text
    assert all(name in text for name in SUBCOMMAND_HELP)
    code, text = run(capsys, "bogus")
    assert code == 4 and "no subcommand 'bogus'" in text and "monitor" in text


def test_the_main_help_shows_the_subcommands(capsys):
    code, text = run(capsys, "--help")
    assert code == 0
    head = text.split("options:", 1)[0]  # before the long option list, where it is seen
    assert all(f"  {name} " in head for name in SUBCOMMAND_HELP), head


@pytest.mark.parametrize("sub", ["judge", "export"])
def test_judge_and_export_help_have_examples(capsys, sub):
    code, text = run(capsys, sub, "--help")
    assert code == 0 and "examples:" in text and f"sdi12-conform {sub} " in text


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (("list", "--help"), ("--role {sensor,recorder}", "recorder's")),
        (("faults", "--help"), ("--role {sensor,recorder}", "recorder-faults")),
        (("calibrate", "--help"), ("does the interface echo", "driver")),
    ],
)
def test_options_have_help_text(capsys, argv, words):
    code, text = run(capsys, *argv)
    assert code == 0
    flat = " ".join(text.split())
    assert all(w in flat for w in words), text


def test_faults_lists_the_recorder_faults(capsys):
    code, text = run(capsys, "faults", "--role", "recorder")
    assert code == 0
    assert f"{len(RECORDER_FAULTS)} recorder faults" in text
    assert all(name in text for name in RECORDER_FAULTS)


@pytest.mark.parametrize(
    ("argv", "meant"),
    [
        (("--port", "sim://?faults=no-service-requst"), "no-service-request"),
        (("matrix", "--faults", "no-service-requst"), "no-service-request"),
        (("--port", "sim://?profile=crc-ignord"), "crc-ignored"),
        (
            ("--role", "recorder", "--port", "sim://?recorder-faults=no-retrie"),
            "no-retries",
        ),
    ],
)
def test_an_unknown_name_gets_did_you_mean(capsys, tmp_path, argv, meant):
    code, text = run(
        capsys, *argv, *(() if argv[0] == "matrix" else ("--report-dir", str(tmp_path)))
    )
    assert code == 4, text
    if meant is not None:
        assert f"did you mean {meant}" in text, text


def test_a_url_typo_gets_the_url_form_not_the_cable(capsys, tmp_path):
    code, text = run(capsys, "--port", "rfc2217//127.0.0.1:4001", "--report-dir", str(tmp_path))
    assert code == 4
    assert "did you mean rfc2217://127.0.0.1:4001" in text and "cable" not in text, text


@pytest.mark.parametrize("sub", ["monitor", "calibrate"])
def test_a_missing_port_suggests_only_what_the_subcommand_accepts(capsys, tmp_path, sub):
    """Seen: both suggested --port sim, which both then refuse."""
    extra = ("--report-dir", str(tmp_path)) if sub == "monitor" else ()
    code, text = run(capsys, sub, "--port", "/dev/ttyUSB9", *extra)
    assert code == 4, text
    assert "does not exist" in text and "--port sim" not in text, text
    code, text = run(capsys, sub, "--port", "sim")
    assert code == 4  # and indeed it is refused
    code, text = run(capsys, "--port", "/dev/ttyUSB9", "--report-dir", str(tmp_path / "main"))
    assert code == 4 and "--port sim" in text  # the main command takes it


def test_emulate_with_a_port_out_of_range_is_a_usage_error(capsys):
    code, text = run(capsys, "emulate", "--listen", "127.0.0.1:99999")
    assert code == 4, text
    assert "internal error" not in text and "0..65535" in text


def _verdicts(where, *, complete=True, fail=0, error=0, inconclusive=3):
    where.mkdir(parents=True, exist_ok=True)
    counts = {"PASS": 5, "FAIL": fail, "ERROR": error, "INCONCLUSIVE": inconclusive}
    data = {"run": {"complete": complete}, "summary": {"verdict": "INCOMPLETE", "counts": counts}}
    (where / "verdicts.json").write_text(json.dumps(data))


def test_a_watch_that_ended_as_asked_with_nothing_broken_exits_0(tmp_path):
    """Seen: `monitor --duration 60` ended as asked and said INCOMPLETE, exit 2: the rules
    the bus never exercised, INCONCLUSIVE, made the monitoring itself look cut short."""
    said = []
    _verdicts(tmp_path / "ok" / "sensor")
    _verdicts(tmp_path / "ok" / "recorder")
    assert heard_as_asked(tmp_path / "ok", said.append) == 0
    assert "monitoring complete" in said[0] and "6 requirement(s) INCONCLUSIVE" in said[0]
    for name, kw in (("cut", {"complete": False}), ("err", {"error": 1}), ("fail", {"fail": 1})):
        _verdicts(tmp_path / name / "sensor", **kw)
        assert heard_as_asked(tmp_path / name, said.append) == 2, name
    assert heard_as_asked(tmp_path / "none", said.append) == 2


# -- counts and notes: one vocabulary ----------------------------------------------------------
def test_a_partial_run_counts_what_it_selected_once(capsys, tmp_path):
    """Seen: "2 of 106 judged, 104 N/A, 104 not selected" (the 104 counted twice); and
    "running 1 conformance cases"."""
    code, text = run(capsys, "--port", "sim", "-k", "identification", "--report-dir", str(tmp_path))
    assert code == 0, text
    assert "running 1 conformance case\n" in text
    assert "2 selected testable requirements judged; 104 of 106 not selected" in text, text
    assert "104 N/A" not in text


def test_a_req_says_why_it_judged_more_and_a_forced_version_says_it_differs(capsys, tmp_path):
    code, text = run(
        capsys,
        "--port", "sim://?version=1.3", "--sdi-version", "1.4", "--req", "R-4.4.6-02",
        "--report-dir", str(tmp_path),
    )  # fmt: skip
    flat = " ".join(text.split())
    # test_service_request's five, and the two of concurrent measurements the whole-run
    # case over every measurement made again judges beside them (truth31)
    assert "--req R-4.4.6-02 names 1 requirement(s); 7 were judged" in flat, text
    assert "also judge 6 other(s)" in flat and "a case runs whole" in flat
    assert "--sdi-version 1.4 judged the device by the v1.4 rules, but its aI! reports v1.3" in flat


def test_a_summary_before_the_sensor_was_found_says_so():
    """Seen after an early Ctrl-C: "DUT None · SDI-12 None"."""
    from conformance.reports.console import _identity_lines

    data = {
        "dut": {"address": None, "sdi12_version": None, "identification": None},
        "run": {"role": "sensor", "port": "sim", "link": {"kind": "sim"}},
    }
    first = _identity_lines(data)[0]
    assert "None" not in first and "not found yet" in first
