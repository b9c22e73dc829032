"""Runs that cannot mix: a report folder per run, a refusal for a folder a live run holds, and
a console verdict and exit code from the run's own results (issue 19's first blocker: two runs
started together wrote one folder and printed each other's verdict)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conformance import report_folder
from conformance.cli import main
from conformance.options import UsageError
from tests.support.paths import ROOT

FAULTY = "sim://?faults=no-service-request"
QUICK = ("--req", "R-4.4.6-02")  # one requirement the fault breaks: a run of about a second

# Each child announces itself, waits until every child has, then runs the command line: the
# two runs start within milliseconds of each other, as `cmd & cmd &` in a shell does.
CHILD = """
import os, sys, time
from pathlib import Path
from conformance.cli import main
me, n, gate = sys.argv[1], int(sys.argv[2]), Path(sys.argv[3])
(gate / me).touch()
while len(list(gate.iterdir())) < n:
    time.sleep(0.001)
sys.exit(main(sys.argv[4:]))
"""


def start_together(cwd: Path, *argvs: list[str]) -> list[subprocess.CompletedProcess[str]]:
    gate = cwd / f"gate-{os.urandom(4).hex()}"
    gate.mkdir()
    env = os.environ | {"PYTHONPATH": str(ROOT)}
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", CHILD, str(i), str(len(argvs)), str(gate), *argv],
            cwd=cwd,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for i, argv in enumerate(argvs)
    ]
    done = []
    for p in procs:
        out, err = p.communicate(timeout=300)
        done.append(subprocess.CompletedProcess(p.args, p.returncode, out, err))
    return done


def report_of(proc: subprocess.CompletedProcess[str], cwd: Path) -> Path:
    """The folder the run said it wrote (its console summary's ``report:`` line)."""
    found = re.search(r"^report: (\S+)/report\.html$", proc.stdout, re.M)
    assert found, proc.stdout + proc.stderr
    return cwd / found.group(1)


def test_two_runs_started_together_each_get_their_own_folder_and_verdict(tmp_path):
    for _ in range(3):
        faulty, clean = start_together(
            tmp_path, ["--port", FAULTY, *QUICK], ["--port", "sim", *QUICK]
        )
        assert faulty.returncode == 1, faulty.stdout + faulty.stderr
        assert "verdict: NON-COMPLIANT" in faulty.stdout
        assert clean.returncode == 0, clean.stdout + clean.stderr
        assert "verdict: COMPLIANT" in clean.stdout
        assert f"port {FAULTY}" in faulty.stdout and "port sim ·" in clean.stdout
        folders = report_of(faulty, tmp_path), report_of(clean, tmp_path)
        assert folders[0] != folders[1]
        for folder, port, verdict in zip(
            folders, (FAULTY, "sim"), ("NON-COMPLIANT", "COMPLIANT"), strict=True
        ):
            data = json.loads((folder / "verdicts.json").read_text(encoding="utf-8"))
            assert (data["run"]["port"], data["summary"]["verdict"]) == (port, verdict)
            assert not (folder / report_folder.LOCK_NAME).exists()  # let go at the end


def test_two_runs_named_into_one_folder_never_swap_verdicts(tmp_path):
    shared = tmp_path / "shared"
    for _ in range(3):
        faulty, clean = start_together(
            tmp_path,
            ["--port", FAULTY, *QUICK, "--report-dir", str(shared)],
            ["--port", "sim", *QUICK, "--report-dir", str(shared)],
        )
        for proc, code, verdict in ((faulty, 1, "NON-COMPLIANT"), (clean, 0, "COMPLIANT")):
            if proc.returncode == 4:  # the other run held the folder: refused, one line
                assert "holds a run in progress" in proc.stderr
                assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
                assert "verdict:" not in proc.stdout
            else:
                assert proc.returncode == code, proc.stdout + proc.stderr
                assert f"verdict: {verdict}" in proc.stdout
        assert {faulty.returncode, clean.returncode} != {4}  # one of them ran
        assert not (shared / report_folder.LOCK_NAME).exists()


@pytest.fixture
def live_pid():
    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    yield holder.pid
    holder.kill()
    holder.wait()


def test_a_folder_a_live_run_holds_is_refused_with_exit_4(tmp_path, live_pid, capsys):
    (tmp_path / report_folder.LOCK_NAME).write_text(f"{live_pid}\n")
    code = main(["--port", "sim", *QUICK, "--report-dir", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 4
    assert f"holds a run in progress (pid {live_pid})" in err
    assert len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "verdicts.json").exists()
    assert (tmp_path / report_folder.LOCK_NAME).read_text().strip() == str(live_pid)


def test_the_plugin_refuses_a_held_folder_too(tmp_path, live_pid):
    """``pytest --pyargs testcases.sensor`` without the CLI takes the same lock."""
    (tmp_path / report_folder.LOCK_NAME).write_text(f"{live_pid}\n")
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:randomly", "--pyargs", "testcases.sensor",
         "--sdi12-port", "sim", "--sdi12-report-dir", str(tmp_path), "-p", "no:html",
         "-k", "identification"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 4, proc.stdout + proc.stderr
    assert "holds a run in progress" in proc.stderr
    assert not (tmp_path / "verdicts.json").exists()


def test_a_stale_lock_of_a_dead_process_is_taken_over(tmp_path, capsys):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / report_folder.LOCK_NAME).write_text(f"{dead.pid}\n")
    assert main(["--port", "sim", *QUICK, "--report-dir", str(tmp_path)]) == 0
    assert "verdict: COMPLIANT" in capsys.readouterr().out
    assert (tmp_path / "verdicts.json").exists()
    assert not (tmp_path / report_folder.LOCK_NAME).exists()


def test_the_summary_is_the_runs_own_not_the_file_on_disk(tmp_path, capsys, monkeypatch):
    """A verdicts.json another process rewrote after this run wrote it changes nothing the
    command prints or exits on."""
    from conformance.reports import writers

    def overwrite(run, directory):
        path = directory / "verdicts.json"
        forged = json.loads(path.read_text(encoding="utf-8"))
        forged["summary"]["verdict"] = "COMPLIANT"
        forged["run"]["port"] = "someone else's"
        path.write_text(json.dumps(forged), encoding="utf-8")
        return path

    forger = writers.ReportWriter("verdicts.json", "a forgery after the real one", overwrite)
    monkeypatch.setattr(writers, "REPORT_WRITERS", (*writers.REPORT_WRITERS, forger))
    code = main(["--port", FAULTY, *QUICK, "--report-dir", str(tmp_path)])
    out = capsys.readouterr().out
    assert json.loads((tmp_path / "verdicts.json").read_text())["summary"]["verdict"] == "COMPLIANT"
    assert code == 1
    assert "verdict: NON-COMPLIANT" in out and "someone else's" not in out


def test_default_folders_are_new_every_time(tmp_path):
    made = [report_folder.new_report_dir("sensor", tmp_path) for _ in range(3)]
    assert len(set(made)) == 3 and all(p.is_dir() for p in made)
    assert made[1].name == made[0].name + "-2" or made[1].name[:15] != made[0].name[:15]


def test_a_lock_nests_within_one_process_and_goes_with_the_outermost(tmp_path):
    lock = tmp_path / report_folder.LOCK_NAME
    report_folder.acquire(tmp_path)
    report_folder.acquire(tmp_path)  # e.g. monitor, then the judging it ends with
    report_folder.release(tmp_path)
    assert lock.read_text().strip() == str(os.getpid())
    report_folder.release(tmp_path)
    assert not lock.exists()


def test_an_unreadable_lock_is_not_a_refusal_forever(tmp_path):
    (tmp_path / report_folder.LOCK_NAME).write_text("garbage")
    with report_folder.held(tmp_path):
        assert (tmp_path / report_folder.LOCK_NAME).read_text().strip() == str(os.getpid())


def test_refusal_names_the_holder(tmp_path, live_pid):
    (tmp_path / report_folder.LOCK_NAME).write_text(f"{live_pid}\n")
    with pytest.raises(UsageError, match=f"pid {live_pid}"):
        report_folder.acquire(tmp_path)


def test_judge_writes_nothing_into_a_folder_a_live_run_holds(tmp_path, live_pid, capsys):
    """``judge capture.sr --report-dir HELD`` refuses before decoding into it (the decoded
    capture.jsonl used to be written there first)."""
    run = tmp_path / "run"
    assert main(["--port", "sim", *QUICK, "--report-dir", str(run)]) == 0
    capture = tmp_path / "run.sr"
    assert main(["export", str(run), "--to", "sr", "-o", str(capture)]) == 0
    held = tmp_path / "held"
    held.mkdir()
    (held / report_folder.LOCK_NAME).write_text(f"{live_pid}\n")
    capsys.readouterr()
    assert main(["judge", str(capture), "--report-dir", str(held)]) == 4
    assert f"holds a run in progress (pid {live_pid})" in capsys.readouterr().err
    assert sorted(p.name for p in held.iterdir()) == [report_folder.LOCK_NAME]
