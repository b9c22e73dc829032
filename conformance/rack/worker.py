"""One DUT's run inside a rack worker: the code execnet sends to the worker process.

The rack starts one worker process per DUT (:mod:`.pool`) and hands this module's source to
it (``gateway.remote_exec``); there it runs as ``__channelexec__`` with a ``channel`` to the
rack. It receives one job (the DUT's run options), runs the same checks, plan and suite a
single ``sdi12-conform --port`` run does (:func:`conformance.cli.run_suite`) into the job's
report folder, and sends back one result: the exit status, the report folder, what the
verdicts say, the error lines, and, for a worker on another host, the folder's files.

A ``"stop"`` message (the rack's Ctrl-C) is turned into this process's own SIGINT, so the run
stops exactly as a single run stopped by Ctrl-C does: at once inside a case, its report
written with ``complete: false``, exit 2. The worker puts itself in a process group of its
own, so a Ctrl-C typed at the terminal reaches the rack alone and each worker is stopped once,
by the rack, whether it runs on this host or another.

Only the standard library is imported at the top: the module runs where ``conformance`` may
be installed elsewhere than on the rack's host (an ssh worker's own Python). Nothing in
``conformance`` imports it: it is a program of its own, whose source the pool sends to each
worker, as ``sdi12-conform`` is one (and, like it, it runs the main command's
:func:`conformance.cli.run_suite`).
"""

from __future__ import annotations

import contextlib
import io
import os
import platform
import signal
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

#: the files of a report folder a worker keeps to itself (the run lock)
_NOT_SHIPPED = {".sdi12-conform.lock"}


def _own_process_group() -> None:
    """Leave the terminal's foreground group: its Ctrl-C is the rack's to pass on."""
    with contextlib.suppress(OSError, AttributeError):
        os.setpgrp()


def _stop_on_message(channel: Any) -> None:
    """A ``"stop"`` from the rack interrupts this process as Ctrl-C would (once: a second
    interrupt inside a case's teardown would cut the report it is writing)."""
    from conformance.interrupts import GUARD
    from conformance.rack.protocol import STOP

    def on_message(item: Any) -> None:
        if item == STOP and not GUARD.requested:
            os.kill(os.getpid(), signal.SIGINT)

    channel.setcallback(on_message)


def shipped_files(folder: Path) -> dict[str, bytes]:
    """Every file of a report folder by its path inside it, for a rack on another host."""
    return {
        path.relative_to(folder).as_posix(): path.read_bytes()
        for path in sorted(folder.rglob("*"))
        if path.is_file() and path.name not in _NOT_SHIPPED
    }


def _run(options: Any, plan: str, errors: io.StringIO) -> tuple[int, dict[str, Any] | None]:
    """The single-port run, its console kept off the rack's terminal and its error lines
    kept for the rack's summary."""
    from rich.console import Console

    from conformance.cli import run_suite
    from conformance.exits import EXIT_INCOMPLETE, EXIT_INTERNAL

    console = Console(file=io.StringIO(), soft_wrap=True)
    with contextlib.redirect_stderr(errors):
        try:
            return run_suite(options, console, plan=plan)
        except KeyboardInterrupt:
            print("interrupted", file=errors)
            return EXIT_INCOMPLETE, None
        except Exception as exc:  # a bug in the tool: the rack reports it, exit 3
            print(f"internal error: {type(exc).__name__}: {exc}", file=errors)
            return EXIT_INTERNAL, None


def run_dut(job: dict[str, Any]) -> dict[str, Any]:
    """Run one DUT as the job says; the result the rack's summary is made from.

    ``job``: ``options`` (RunOptions fields), ``plan``, ``report_dir`` (None: a temporary
    folder whose files are sent back), ``declaration_text`` (the declaration's content, for
    a worker that cannot read the rack's files)."""
    from conformance.interrupts import GUARD
    from conformance.rack.protocol import slim_document
    from conformance.run import RunOptions

    began = time.monotonic()
    options = RunOptions(**job["options"])
    with tempfile.TemporaryDirectory(prefix="sdi12-rack-") as tmp:
        ship = job.get("report_dir") is None
        folder = Path(job["report_dir"]) if not ship else Path(tmp) / "run"
        options.report_dir = str(folder)
        if job.get("declaration_text") is not None:
            name = Path(options.declaration or "declaration.toml").name  # the rack's name
            options.declaration = str(Path(tmp) / name)
            Path(options.declaration).write_text(job["declaration_text"], encoding="utf-8")
        errors = io.StringIO()
        code, document = _run(options, job.get("plan") or "auto", errors)
        GUARD.close()
        exists = folder.is_dir()
        return {
            "exit_code": code,
            "folder": str(folder) if exists and not ship else None,
            "document": slim_document(document),
            "errors": [line for line in errors.getvalue().splitlines() if line.strip()],
            "files": shipped_files(folder) if ship and exists else None,
            "wall_s": round(time.monotonic() - began, 3),
            "host": platform.node(),
            "pid": os.getpid(),
        }


def cannot_run(why: str) -> dict[str, Any]:
    """The result of a worker whose Python cannot run the tool (not installed there)."""
    return {
        "exit_code": 3,  # exits.EXIT_INTERNAL: the rack's tool could not run on that host
        "folder": None,
        "document": None,
        "errors": [why],
        "files": None,
        "wall_s": None,
        "host": platform.node(),
        "pid": os.getpid(),
    }


def serve(channel: Any) -> None:
    """The worker's life: one job in, one result out, a stop heard in between."""
    _own_process_group()
    try:
        from conformance.interrupts import GUARD
    except ImportError as exc:  # a host whose Python has no sdi12-conform
        channel.receive()
        channel.send(cannot_run(
            f"the worker's Python ({sys.executable}) cannot run sdi12-conform: "
            f"{type(exc).__name__}: {exc}; install sdi12-conform there, or name another "
            "python in its spec (//python=PATH)"
        ))  # fmt: skip
        return

    GUARD.reset()
    GUARD.install()  # the main thread (execmodel main_thread_only): Ctrl-C is the run's
    job = channel.receive()
    _stop_on_message(channel)
    channel.send(run_dut(job))


if __name__ == "__channelexec__":
    serve(channel)  # type: ignore[name-defined]  # noqa: F821  (execnet's global)
