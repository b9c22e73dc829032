"""Whole live runs (``sdi12-conform --port PORT --role ROLE --report-dir DIR``, in this
process) made once per test session and copied to each test that reads one.

Many modules judge, export or replay the same run (the clean sensor, the clean recorder, a
fault or two): each made its own, about 1 s of CPU a run (``wrong-crc`` 2.4 s), several times
in one module and again in the next. The run depends on nothing but its port and role (the
simulated bus runs in virtual time), so one made run serves them all. Under pytest-xdist the
workers share it too: it is made in the session's common temporary folder (the workers'
``basetemp``'s parent, as pytest-xdist's documentation does for session data), the first
worker to want it making it under a file lock while the others wait for it.

Each test gets its own copy (:func:`copied_run`): a test may write beside the run (``export``
puts its capture there by default) and never sees another test's files. What a copy cannot
be is the folder the run was made in: the run's options note names that folder, so a test
that compares a run's transcript with one it makes itself in its own folder keeps its own run.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
from pathlib import Path

import pytest

from conformance.cli import main


def common_folder(factory: pytest.TempPathFactory) -> Path:
    """The folder every process of this session shares: the workers' ``basetemp`` parent
    under pytest-xdist, the session's own ``basetemp`` without it."""
    base = factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def made_run(factory: pytest.TempPathFactory, port: str, role: str = "sensor") -> tuple[Path, int]:
    """The folder of the live run of ``role`` against ``port`` and the main command's exit
    code, made by the first process of the session that asks (under a lock the others wait
    on). Read the folder, never write to it."""
    key = hashlib.sha256(f"{role}\0{port}".encode()).hexdigest()[:16]
    runs = common_folder(factory) / "shared-runs"
    runs.mkdir(exist_ok=True)
    folder, code_file = runs / key, runs / f"{key}.exit"
    with open(runs / f"{key}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
        if not code_file.is_file():
            shutil.rmtree(folder, ignore_errors=True)  # a run cut short in an earlier attempt
            code = main(["--port", port, "--role", role, "--report-dir", str(folder)])
            if not (folder / "verdicts.json").is_file():
                raise AssertionError(f"the {role} run against {port} wrote no verdicts.json")
            code_file.write_text(str(code))  # last: the run is whole
        return folder, int(code_file.read_text())


def copied_run(
    factory: pytest.TempPathFactory, into: Path, port: str, role: str = "sensor"
) -> tuple[Path, int]:
    """A copy, at ``into`` (which must not exist), of the session's live run of ``role``
    against ``port`` (:func:`made_run`), the test's own to read and write beside, and the
    main command's exit code for it."""
    folder, code = made_run(factory, port, role)
    shutil.copytree(folder, into)
    return into, code
