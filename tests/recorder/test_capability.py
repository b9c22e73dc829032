"""Issue 20: a recorder declaration ([recorder] of --declaration) and what it does to the
verdicts. An absent capability the standard lets a recorder lack is not asked (N/A citing
the declaration); one it requires is asked and judged as without a declaration (a FAIL says
the declaration does not excuse it); the rules on how a declared-absent kind is used are N/A
when the recorder indeed never sent it."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.declaration import DeclarationError, load_declaration
from conformance.harness.protocol import HarnessProtocolError, PlanKind, Role, parse_plan
from conformance.matrices.recorder_matrix import run_recorder_suite
from conformance.protocol.commands import Kind
from conformance.recorder.capability import cannot_finding
from conformance.recorder.drivers import CANNOT_EXIT, Trigger
from conformance.recorder.faults import LacksCommandsRecorder
from conformance.recorder_jobs import Request, Task
from conformance.verdicts import Finding, Verdict
from tests.support.paths import ROOT


def write(tmp_path: Path, text: str, name: str = "recorder.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def verdicts(data: dict) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in data["requirements"]}


def details(data: dict, rid: str) -> list[str]:
    return [f["detail"] for r in data["requirements"] if r["id"] == rid for f in r["findings"]]


def run(port: str, declaration: Path | None = None, **options: object) -> dict:
    if declaration:
        options["declaration"] = str(declaration)
    return run_recorder_suite(port, **options)


# -- parsing ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "line", "says"),
    [
        ("[recorder]\nconcurent = false\n", 3, "[recorder] concurent: unknown key"),
        ("[recorder]\ncrc = 1\n", 3, "[recorder] crc: must be a true/false"),
        ('[recorder]\ncrc = true\ncommands = "M D"\n', 4, "[recorder] commands: must be a list"),
        ('[recorder]\ncommands = ["M", "D", "Q"]\n', 3, "unknown command kind(s) ['Q']"),
        ('[recorder]\naddresses = "0-Z"\n', 3, "mixes digits and letters"),
        ('[recorder]\naddresses = "0-9,$"\n', 3, "neither an address nor a range"),
        ('[recorder]\ncommands = ["M", "D", "CC"]\nconcurrent = false\n', 4, "lists CC"),
    ],
)
def test_a_bad_recorder_table_is_refused_with_file_and_line(tmp_path, body, line, says):
    path = write(tmp_path, 'sdi12_version = "1.3"\n' + body)
    with pytest.raises(DeclarationError) as err:
        load_declaration(path)
    assert str(err.value).startswith(f"{path}:{line}: ")
    assert says in str(err.value)


def test_the_recorder_table_is_read_and_the_sensor_keys_are_unchanged(tmp_path):
    path = write(
        tmp_path,
        'address = "3"\nsdi12_version = "1.4"\n[features]\ncontinuous = false\n'
        '[recorder]\ncommands = ["?", "!", "I", "A", "M", "D"]\nhigh_volume = false\n'
        'addresses = "0-9,A-C"\n',
    )
    declared = load_declaration(path)
    assert (declared.address, declared.sdi12_version) == ("3", "14")
    assert declared.feature("continuous") is False
    rec = declared.recorder
    assert rec is not None and rec.commands == frozenset("?!IAMD")
    assert rec.high_volume is False and rec.crc is None
    assert rec.addresses == frozenset("0123456789ABC")
    assert rec.where["addresses"] == f"{path}:8"
    assert load_declaration(write(tmp_path, 'address = "0"\n', "sensor.toml")).recorder is None


# -- judged runs --------------------------------------------------------------------------

CONCURRENT = ("R-4.4.7-06", "R-4.4.7-07")


def test_a_declared_mandatory_absence_stays_failed_and_its_dependent_rules_become_na(tmp_path):
    """no-concurrent lacks aC!-type commands. Declared so, R-4.4.7-08 and R-4.4-02 still FAIL
    (a v1.2+ recorder must support aC!), the FAIL saying the declaration does not excuse it;
    the concurrent waits and storage, INCONCLUSIVE without the declaration, are N/A citing
    it; every other rule keeps its verdict."""
    port = "sim:?recorder-faults=no-concurrent"
    path = write(tmp_path, 'sdi12_version = "1.4"\n[recorder]\nconcurrent = false\n')
    plain, declared = verdicts(run(port)), run(port, path)
    assert [plain[r] for r in CONCURRENT] == ["INCONCLUSIVE", "INCONCLUSIVE"]
    got = verdicts(declared)
    assert [got[r] for r in CONCURRENT] == ["N/A", "N/A"]
    for rid in CONCURRENT:
        assert all(f"[recorder] concurrent = false ({path}:3)" in d for d in details(declared, rid))
    assert got["R-4.4.7-08"] == got["R-4.4-02"] == plain["R-4.4.7-08"] == "FAIL"
    assert any("does not excuse it" in d for d in details(declared, "R-4.4.7-08"))
    assert {r: v for r, v in got.items() if r not in CONCURRENT} == {
        r: v for r, v in plain.items() if r not in CONCURRENT
    }
    assert declared["dut"]["declaration"] == str(path)
    assert any("declared without aC!, aCC!" in a for a in declared["dut"]["assumptions"])


def test_high_volume_declared_absent_on_a_v14_recorder(tmp_path):
    port = "sim:?recorder-faults=no-high-volume"
    path = write(tmp_path, 'sdi12_version = "1.4"\n[recorder]\nhigh_volume = false\n')
    got = verdicts(run(port, path))
    assert got["R-5.1-04"] == got["R-5.2-08"] == "N/A"
    assert got["R-5.4-01"] == "FAIL"


def test_a_declared_absence_the_recorder_contradicts_is_judged_on_the_wire(tmp_path):
    """The golden recorder sends aC! although the declaration says it cannot: what it did is
    judged (PASS), not excused."""
    path = write(tmp_path, 'sdi12_version = "1.4"\n[recorder]\nconcurrent = false\n')
    data = run("sim", path)
    assert data["summary"]["verdict"] == "COMPLIANT"
    got = verdicts(data)
    assert [got[r] for r in (*CONCURRENT, "R-4.4.7-08")] == ["PASS"] * 3


def letterless() -> LacksCommandsRecorder:
    """A logger that cannot address letters (a recorder= program for the sim port)."""
    return LacksCommandsRecorder(unreachable="Az")


def no_verify() -> LacksCommandsRecorder:
    return LacksCommandsRecorder(lacks=frozenset({Kind.VERIFY}))


PROGRAM = "sim:?recorder=tests.recorder.test_capability:"


def test_an_optional_capability_declared_absent_is_not_asked_and_na(tmp_path):
    """Letter addresses are a MAY (R-4.3-04): declared "0-9", A and z are not asked, R-4.3-04
    is N/A citing the declaration, R-4.3-03 still judged on 0-9."""
    path = write(tmp_path, 'sdi12_version = "1.4"\n[recorder]\naddresses = "0-9"\n')
    with_report = tmp_path / "run"
    from conformance.conduct import run_into

    data = run_into(with_report, PROGRAM + "letterless", "recorder", declaration=str(path))
    got = verdicts(data)
    assert got["R-4.3-04"] == "N/A" and got["R-4.3-03"] == "PASS"
    assert details(data, "R-4.3-04") == [
        "not applicable: letter addresses are optional (MAY) and the declaration says the "
        f'recorder polls only "0-9" ({path}:3); none asked'
    ]
    notes = [
        json.loads(line)["text"]
        for line in (with_report / "transcript.jsonl").read_text().splitlines()
        if '"note"' in line
    ]
    assert any(n.startswith("not asked: A! needs address A, declared absent") for n in notes)
    assert data["summary"]["verdict"] == "COMPLIANT"
    # the golden recorder can address letters, and would (R-4.3-04 PASS) if it were asked
    golden = run("sim", path)
    assert verdicts(golden)["R-4.3-04"] == "N/A" and verdicts(run("sim"))["R-4.3-04"] == "PASS"


def test_digits_declared_absent_are_asked_and_still_fail(tmp_path):
    path = write(tmp_path, 'sdi12_version = "1.4"\n[recorder]\naddresses = "0-4"\n')
    data = run("sim:?recorder-faults=addresses-0-4-only", path)
    assert verdicts(data)["R-4.3-03"] == "FAIL"
    assert any("does not excuse it" in d for d in details(data, "R-4.3-03"))


def test_a_logger_without_av_fails_r_4_4_02_declared_or_not(tmp_path):
    path = write(
        tmp_path,
        '[recorder]\ncommands = ["?", "!", "I", "A", "M", "D", "MC", "C", '
        '"CC", "R", "RC", "HA", "HB", "DB", "X", "IM"]\n',
    )
    plain = verdicts(run(PROGRAM + "no_verify"))
    declared = run(PROGRAM + "no_verify", path)
    assert plain["R-4.4-02"] == verdicts(declared)["R-4.4-02"] == "FAIL"
    assert any(f"commands lists no V ({path}:2)" in d for d in details(declared, "R-4.4-02"))


def test_without_a_declaration_the_assumptions_say_every_job_was_asked():
    data = run("sim")
    assert any(
        a.startswith("no recorder declaration (none given): every job asked")
        for a in data["dut"]["assumptions"]
    )


# -- "cannot JOB": a harness's answer, a trigger's exit code 3 ------------------------------

HARNESS = f"exec:{sys.executable} {ROOT / 'examples/python/recorder_harness.py'}"
NEAR = {"keyword": "test_addresses or test_every_basic_command or test_logged_values"}


def test_a_harness_that_cannot_do_a_job(monkeypatch):
    """``cannot`` for the addresses job: R-4.3-03 (MUST, addresses 0-9) FAILs on the
    recorder's own words, R-4.3-04 (MAY, letters) is N/A citing them; ``cannot`` for the
    basic aM! job FAILs R-4.4-02. The rules judged on other jobs keep their verdicts."""
    # the harness process imports this tree's conformance, not another installed one
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    plain = run(HARNESS, None, **NEAR)
    said = run(f"{HARNESS} --cannot addresses,service-request", None, **NEAR)
    got, before = verdicts(said), verdicts(plain)
    assert before["R-4.3-03"] == before["R-4.4-02"] == "PASS"
    assert got["R-4.3-03"] == got["R-4.4-02"] == "FAIL"
    assert any(
        d.startswith("the recorder said it cannot do addresses (this logger cannot do addresses)")
        and "R-4.3-03 (MUST)" in d
        for d in details(said, "R-4.3-03")
    )
    assert any("cannot do service-request" in d for d in details(said, "R-4.4-02"))
    assert got["R-4.3-04"] == "N/A"
    assert any("cannot do addresses" in d and "MAY" in d for d in details(said, "R-4.3-04"))
    rest = set(before) - {"R-4.3-03", "R-4.3-04", "R-4.4-02"}
    assert {r: got[r] for r in rest} == {r: before[r] for r in rest}


def test_cannot_is_a_recorder_plan_only():
    plan = parse_plan("cannot no aC! here", Role.RECORDER, 0)
    assert (plan.kind, plan.reason) == (PlanKind.CANNOT, "no aC! here")
    assert parse_plan("cannot", Role.RECORDER, 0).reason == ""
    with pytest.raises(HarnessProtocolError, match="recorder harnesses only"):
        parse_plan("cannot", Role.SENSOR, 0)


def test_a_job_of_optional_commands_only_is_na_when_the_recorder_cannot():
    """A job that needs only what the standard lets a recorder lack (letter addresses): every
    rule of it is N/A, and what only the missing job left undecided is dropped."""
    undecided = Finding("R-4.3-01", Verdict.INCONCLUSIVE, "nothing observed")
    kept = Finding("R-4.3-01", Verdict.FAIL, "seen on another job", evidence=["x"], observed=1)
    findings = [undecided, kept]
    got = cannot_finding("R-4.3-01", "letters", "", ("A!", "z!"), findings, "14")
    assert got is not None and got.verdict is Verdict.NA
    assert "the job needs only optional capabilities" in got.detail
    assert findings == [kept]
    mandatory = cannot_finding("R-4.3-03", "digits", "", ("0!", "A!"), [], "13")
    assert mandatory is not None and mandatory.verdict is Verdict.FAIL
    assert mandatory.evidence == ["the recorder said it cannot do digits"]
    assert cannot_finding("R-7.0-02", "digits", "", ("0!",), [], "13") is None


def test_a_trigger_exiting_with_3_says_it_cannot(tmp_path):
    request = Request(Task.MEASURE, ("0C!",))
    out = Trigger("echo 'no concurrent measurements' >&2; exit 3", timeout=10).act(
        "concurrent-two",
        request,
        None,  # type: ignore[arg-type]
    )
    assert out.cannot == "no concurrent measurements"
    assert CANNOT_EXIT == 3


@pytest.mark.realtime
def test_a_trigger_that_cannot_do_the_addresses_job(tmp_path):
    out = tmp_path / "report"
    code = main(
        [
            "--port",
            "rfc2217-serve://127.0.0.1:0",
            "--role",
            "recorder",
            "--trigger",
            "echo 'letters only' >&2; exit 3",
            "--report-dir",
            str(out),
            "-k",
            "test_addresses",
        ]
    )
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    got = verdicts(data)
    assert code == 1
    assert got["R-4.3-03"] == "FAIL" and got["R-4.3-04"] == "N/A"
    assert any("cannot do addresses (letters only)" in d for d in details(data, "R-4.3-03"))


# -- the "declared absent" note only where the absence is what failed (outside check, 2026-12-05)


def test_a_fail_about_allowed_commands_is_not_blamed_on_a_declared_absence(tmp_path):
    """R-4.4-02 asks both for the command families (aMC!, declared absent here) and for the
    logged values to be the ones sent. A logger that cuts digits off 0M2!'s values FAILs the
    latter; that FAIL said "declared absent (aMC! ...), but R-4.4-02 requires it ... does not
    excuse it", blaming the absence for a fault in 0M2!'s logging (seen on USDI12, a logger
    that logged a paused D0 reply, run with crc = false declared: docs/kit.md)."""
    path = write(tmp_path, 'sdi12_version = "1.3"\n[recorder]\ncrc = false\n')
    found = details(run("sim:?recorder-faults=truncates-values", path), "R-4.4-02")
    cut = [d for d in found if "digits cut off" in d]
    assert cut, found
    assert not any("declared absent" in d for d in cut), cut


def test_the_note_stays_where_a_finding_names_a_declared_absent_command(tmp_path):
    """Unit level: a FAIL naming aMC! (or naming no command at all, or a list cut short)
    keeps the note; one naming only 0M2! does not."""
    from conformance.recorder.capability import Capabilities

    path = write(tmp_path, 'sdi12_version = "1.3"\n[recorder]\ncrc = false\n')
    caps = Capabilities(load_declaration(path), "13")

    def fail(detail: str, *evidence: str) -> Finding:
        seen = list(evidence) or ["the run"]  # a FAIL needs an evidence line
        return Finding("R-4.4-02", Verdict.FAIL, detail, evidence=seen, observed=1)

    findings = [
        fail("never answered validly: 0MC!, 0V!"),
        fail("pause-once: 0M2!: logged 9 value(s), 6 in valid replies", "pause-once: 0M2!"),
        fail("the logger logged nothing"),
        fail("never answered validly: 0M!, 0M1! (+2 more)"),
    ]
    caps.apply(findings, sent=set())
    assert ["declared absent" in f.detail for f in findings] == [True, False, True, True]


def test_a_tally_list_cut_short_is_read_whole_from_its_evidence(tmp_path):
    """An ESP-IDF logger library (K0I05's esp_sdi12_master, thirtieth round, docs/kit.md)
    cuts the last digit off every value but the last and logs nothing when a service request
    comes: R-4.4-02's logged-values FAIL listed 20 measurements, "(+17 more)" in its detail,
    and kept the "declared absent (aMC! ...) ... does not excuse it" note of a v1.3
    declaration without CRC, though every command it names (in the detail and in the
    tally's ``also:`` evidence lines) was declared present. A list whose rest the evidence
    does not keep still keeps the note, and so does one whose ``also:`` lines name 0MC!."""
    from conformance.judges.tally import Tally
    from conformance.recorder.capability import Capabilities

    path = write(tmp_path, 'sdi12_version = "1.3"\n[recorder]\ncrc = false\n')
    caps = Capabilities(load_declaration(path), "13")

    def tallied(*commands: str) -> Finding:
        tally = Tally(["R-4.4-02"])
        for i, command in enumerate(commands):
            tally.fail("R-4.4-02", f"s{i}: {command}", f"value 1 logged as 22.{i}: digits cut off")
        (finding,) = tally.findings()
        return finding

    allowed = tallied("0M!", "0M1!", "0C!", "0M2!", "1C!", "0C9!")
    hidden_absent = tallied("0M!", "0M1!", "0C!", "0M2!", "0MC!")
    untold = Finding(
        "R-4.4-02",
        Verdict.FAIL,
        "never answered validly: 0M!, 0M1! (+2 more)",
        evidence=["the run"],
        observed=1,
    )
    assert "(+3 more)" in allowed.detail and "(+2 more)" in hidden_absent.detail
    caps.apply([allowed, hidden_absent, untold], sent=set())
    assert "declared absent" not in allowed.detail, allowed.detail
    assert "declared absent" in hidden_absent.detail
    assert "declared absent" in untold.detail
