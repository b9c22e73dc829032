"""Passive judging (issue 11): the rules a recording's traffic can show, judged on it alone.

(a) Judged passively, a simulated run's transcript never contradicts the live run: every
requirement the passive cases decide (PASS, FAIL, WARN) has the live verdict. (b) Where the
traffic shows a fault, its own requirement FAILs (or WARNs) passively. (c) A single-channel
capture of the run (direction inferred) gives the transcript's passive verdicts. (d) Bad input
exits 4 without a traceback, and a capture with no SDI-12 traffic says so.

The default selection keeps a few faults per role; ``matrix`` adds more (minutes).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import jsonschema
import pytest

from conformance.cli import main
from conformance.emulator import FAULTS
from conformance.recorder.faults import RECORDER_FAULTS
from tests.support.paths import ROOT, SHARED
from tests.support.shared_runs import copied_run

EXIT_USAGE = 4
DECIDED = ("PASS", "FAIL", "WARN")
SCHEMA = ROOT / "conformance" / "schemas" / "verdicts-1.json"
HELLO = SHARED / "captures" / "hello_world_8n1_1200.sr"

#: faults whose own requirement the recorded traffic shows (b): each must FAIL/WARN passively
SENSOR_SHOWN = [
    "response-too-early",
    "inter-char-gap",
    "wrong-crc",
    "value-missing-sign",
    "measure-ttt-two-digits",
    "no-service-request",
    "fewer-values-than-announced",
    "parity-error",
]
RECORDER_SHOWN = ["retry-too-early", "short-break", "gappy-commands", "d0-before-ttt"]
#: more of the same, in the slow selection
SENSOR_MORE = [
    "fast-baud",
    "crc-missing",
    "binary-crc-wrong",
    "ident-bad-version",
    "ack-trailing-space",
    "extended-no-crlf",
    "multiline-no-etx",
]
RECORDER_MORE = ["no-break-after-87ms", "late-d0-without-break", "leading-zeros-after-d9"]


def verdicts(run: Path) -> dict[str, str]:
    data = json.loads((run / "verdicts.json").read_text(encoding="utf-8"))
    return {r["id"]: r["verdict"] for r in data["requirements"]}


def live(tmp: Path, port: str, role: str) -> Path:
    out = tmp / "live"
    main(["--port", port, "--role", role, "--report-dir", str(out)])
    assert (out / "verdicts.json").exists()
    return out


LiveRuns = Callable[[str, str], Path]


@pytest.fixture(scope="module")
def live_runs(tmp_path_factory: pytest.TempPathFactory) -> LiveRuns:
    """The folder of the live run of ``role`` against ``port``, copied once into this module:
    several tests judge the same run (the clean sensor, ``crc-missing``, the recorder's
    ``short-break``: eight runs were three), and other modules judge the clean runs too
    (tests/support/shared_runs.py makes each once a session). The tests read the folder and
    write their judgements elsewhere."""
    made: dict[tuple[str, str], Path] = {}

    def run(port: str, role: str) -> Path:
        if (port, role) not in made:
            into = tmp_path_factory.mktemp("live") / "live"
            made[port, role], _code = copied_run(tmp_path_factory, into, port, role)
        return made[port, role]

    return run


def passive(recording: Path, role: str, out: Path, *extra: str) -> dict[str, str]:
    code = main(["judge", str(recording), "--passive", "--role", role, "--report-dir", str(out),
                 *extra])  # fmt: skip
    assert code in (0, 1, 2), code
    return verdicts(out)


def agreement(live_run: dict[str, str], judged: dict[str, str]) -> tuple[int, dict]:
    """How many requirements the passive judging decided, and those it decided otherwise."""
    decided = [rid for rid, v in judged.items() if v in DECIDED]
    differ = {r: (judged[r], live_run.get(r)) for r in decided if judged[r] != live_run.get(r)}
    return len(decided), differ


def _check(
    tmp_path: Path, live_runs: LiveRuns, port: str, role: str, fault: str | None, capsys
) -> None:
    first = live_runs(port, role)
    judged = passive(first, role, tmp_path / "passive")
    before = verdicts(first)
    decided, contradictions = agreement(before, judged)
    with capsys.disabled():
        live_decided = sum(v in DECIDED for v in before.values())
        print(
            f"\n{role} {fault or 'clean'}: passive decided {decided} of the live run's "
            f"{live_decided} decided requirements, {len(contradictions)} contradicted"
        )
    assert not contradictions, contradictions
    assert decided >= (30 if role == "sensor" else 15)
    if fault is not None:
        violates = (FAULTS if role == "sensor" else RECORDER_FAULTS)[fault].violates
        shown = {rid: judged.get(rid) for rid in violates}
        assert any(v in ("FAIL", "WARN") for v in shown.values()), shown


@pytest.mark.slow
@pytest.mark.parametrize("fault", [None, *SENSOR_SHOWN])
def test_sensor_run_judged_passively_agrees(tmp_path, live_runs, fault, capsys):
    port = "sim" if fault is None else f"sim://?faults={fault}"
    _check(tmp_path, live_runs, port, "sensor", fault, capsys)


@pytest.mark.slow
@pytest.mark.parametrize("fault", [None, *RECORDER_SHOWN])
def test_recorder_run_judged_passively_agrees(tmp_path, live_runs, fault, capsys):
    port = "sim" if fault is None else f"sim://?recorder-faults={fault}"
    _check(tmp_path, live_runs, port, "recorder", fault, capsys)


@pytest.mark.matrix
@pytest.mark.parametrize("fault", SENSOR_MORE)
def test_more_sensor_faults_judged_passively(tmp_path, live_runs, fault, capsys):
    _check(tmp_path, live_runs, f"sim://?faults={fault}", "sensor", fault, capsys)


@pytest.mark.matrix
@pytest.mark.parametrize("fault", RECORDER_MORE)
def test_more_recorder_faults_judged_passively(tmp_path, live_runs, fault, capsys):
    _check(tmp_path, live_runs, f"sim://?recorder-faults={fault}", "recorder", fault, capsys)


# crc-missing, not wrong-crc: the same CRC replies to infer directions in, without the
# 93,000 frames of retried reads that make wrong-crc's run the slowest to decode
@pytest.mark.parametrize(
    ("port", "role"),
    [("sim://?faults=crc-missing", "sensor"), ("sim://?recorder-faults=short-break", "recorder")],
)
@pytest.mark.slow
def test_single_wire_capture_gives_the_transcripts_passive_verdicts(
    tmp_path, live_runs, port, role
):
    """Exported with no tool channel, every direction is inferred from the protocol."""
    first = live_runs(port, role)
    from_transcript = passive(first, role, tmp_path / "transcript")
    capture = tmp_path / "run.sr"
    export = ["export", str(first), "--to", "sr", "-o", str(capture), "--no-tool-channel"]
    assert main(export) == 0
    out = tmp_path / "capture"
    assert main(["judge", str(capture), "--role", role, "--report-dir", str(out)]) in (0, 1, 2)
    assert verdicts(out) == from_transcript
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    jsonschema.validate(data, json.loads(SCHEMA.read_text(encoding="utf-8")))
    assert data["run"]["role"] == role
    assert data["run"]["link"]["kind"] == "capture sr"
    assert 0 < data["run"]["link"]["timing_uncertainty_ms"] <= 0.05
    notes = " ".join(data["dut"]["assumptions"])
    assert "polarity (detected)" in notes and "ambiguous split" in notes


@pytest.mark.slow
def test_both_roles_write_two_report_sets(tmp_path, live_runs, capsys):
    first = live_runs("sim://?faults=crc-missing", "sensor")
    capsys.readouterr()  # the live run's own summary
    out = tmp_path / "both"
    code = main(["judge", str(first), "--passive", "--role", "both", "--report-dir", str(out)])
    said = capsys.readouterr().out
    for role in ("sensor", "recorder"):
        assert (out / role / "verdicts.json").exists() and (out / role / "report.html").exists()
        assert (out / role / "junit.xml").exists() and (out / role / "transcript.jsonl").exists()
        assert json.loads((out / role / "verdicts.json").read_text())["run"]["role"] == role
        assert f"{role} rules:" in said
    assert said.count("verdict: ") == 2
    assert code == 1  # the worse of the two: the sensor's missing CRC


def test_a_run_of_this_tool_is_judged_for_its_device_under_test_by_default(
    tmp_path, live_runs, capsys
):
    """A run's recording holds the tool's own stimuli on the other side (short breaks, slow
    characters, invalid addresses on purpose): by default only the judged role's rules, said."""
    first = live_runs("sim://?recorder-faults=short-break", "recorder")
    capsys.readouterr()
    out = tmp_path / "default"
    assert main(["judge", str(first), "--passive", "--report-dir", str(out)]) == 1
    said = capsys.readouterr().out
    assert "recorder rules only: the recording is of this tool's recorder run" in said
    assert not (out / "sensor").exists() and not (out / "recorder").exists()
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    assert data["run"]["role"] == "recorder"
    assert verdicts(out)["R-7.0-02"] == "FAIL"  # the short break, still judged


@pytest.mark.slow
def test_address_limits_the_sensor_rules(tmp_path):
    """The run's sensor sits at 5 and is moved to 7 and back once (R-4.4.4): judged on sensor
    7 alone, only those few exchanges are judged, and the notes say so."""
    first = live(tmp_path, "sim://?address=5", "sensor")
    mine = passive(first, "sensor", tmp_path / "mine", "--address", "5")
    other = passive(first, "sensor", tmp_path / "other", "--address", "7")
    decided = [rid for rid, v in other.items() if v in DECIDED]
    assert sum(v == "PASS" for v in mine.values()) >= 30
    assert len(decided) < sum(v in DECIDED for v in mine.values())
    data = json.loads((tmp_path / "other" / "verdicts.json").read_text(encoding="utf-8"))
    assert "sensor '7' only" in " ".join(data["dut"]["assumptions"])
    for r in data["requirements"]:
        for f in r["findings"]:
            if "checked: " in f["detail"]:
                labels = f["detail"].split("checked: ", 1)[1].rstrip(")").split(", ")
                assert all(label.removeprefix("reply to ")[:1] == "7" for label in labels), f


def test_unseen_rules_are_inconclusive_not_passed(tmp_path, live_runs):
    """A recording with no aHB!: the binary rules are 'not seen in the recording'."""
    first = live_runs("sim", "sensor")
    lines = (first / "transcript.jsonl").read_text(encoding="utf-8").splitlines()
    cut = tmp_path / "short.jsonl"
    cut.write_text("\n".join(lines[:400]) + "\n", encoding="utf-8")
    out = tmp_path / "short"
    passive(cut, "sensor", out)
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    binary = next(r for r in data["requirements"] if r["id"] == "R-5.2-07")
    assert binary["verdict"] == "INCONCLUSIVE"
    assert "not seen in the recording" in binary["findings"][0]["detail"]


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("garbage.bin", bytes(range(256)) * 8, "binary data"),
        ("notjson.jsonl", b"{not json\n", "line 1"),
    ],
)
def test_bad_input_exits_4_plainly(tmp_path, capsys, name, content, words):
    path = tmp_path / name
    path.write_bytes(content)
    assert main(["judge", str(path), "--passive", "--report-dir", str(tmp_path / "o")]) == 4
    err = capsys.readouterr().err
    assert str(path) in err and words in err and "Traceback" not in err


@pytest.mark.skipif(not HELLO.exists(), reason=f"{HELLO} is not on this machine")
def test_capture_without_sdi12_traffic_says_so(tmp_path, capsys):
    assert main(["judge", str(HELLO), "--report-dir", str(tmp_path / "o")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "no SDI-12 traffic" in err and str(HELLO) in err and "Traceback" not in err
