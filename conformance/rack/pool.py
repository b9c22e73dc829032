"""The rack's workers: one process per DUT, started through execnet, fed one job each,
heard as each finishes, stopped together on Ctrl-C.

Why execnet and not an outer pytest-xdist session whose items are the DUTs: each DUT's run
is itself a whole pytest session (``conduct`` calls ``pytest.main`` with the conformance
plugin), its Ctrl-C handling needs the process's main thread and signal handler, and its
result is a verdicts document, not a test outcome. A pytest session nested in an xdist
worker's test would share that worker's plugins, capture and signal handling, and an
interrupt would end the outer session's item rather than leave the DUT's report true. execnet
is the layer under xdist: the same gateways (``popen``, ``ssh=HOST//python=...``,
``socket=...``; ``--tx`` specs read as xdist reads them, ``N*SPEC`` included), the same
``main_thread_only`` execution model xdist uses, so a worker's run has its main thread, and a
channel per worker that carries the job, the result and the stop.

A worker that cannot be started, or dies, or does not stop within :data:`STOP_GRACE` seconds
of a Ctrl-C still gets a row: what its folder holds (a verdicts.json says whether it was
complete) and why there is nothing more.
"""

from __future__ import annotations

import contextlib
import json
import queue
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..exits import EXIT_INCOMPLETE, EXIT_INTERNAL
from ..interrupts import GUARD
from .protocol import STOP, slim_document

#: seconds a stopped worker gets to write its report before it is given up on (a case
#: stops at once on Ctrl-C; writing a whole run's reports takes a second or two)
STOP_GRACE = 60.0
_POLL = 0.2
_CLOSED = object()  # a channel's end, as execnet's callback hands it over


def worker_source() -> str:
    """The worker program's source, which execnet runs in each worker process (what
    ``remote_exec(module)`` would send; read here, never imported into the rack's process)."""
    return Path(__file__).with_name("worker.py").read_text(encoding="utf-8")


def main_thread_spec(spec: str) -> str:
    """The spec with execnet's ``main_thread_only`` model, as xdist makes its workers: the
    job runs in the worker's main thread, where Python delivers SIGINT."""
    return spec if "execmodel=" in spec else f"execmodel=main_thread_only//{spec}"


def lost_result(job: dict[str, Any], why: str, code: int) -> dict[str, Any]:
    """The row of a DUT whose worker sent nothing back: what its own folder shows (a
    verdicts.json written before the worker was lost says how complete the run was)."""
    folder = Path(job["report_dir"]) if job.get("report_dir") else None
    document = None
    if folder is not None and (folder / "verdicts.json").is_file():
        try:
            document = json.loads((folder / "verdicts.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            document = None
    return {
        "exit_code": code,
        "folder": str(folder) if folder is not None and folder.is_dir() else None,
        "document": slim_document(document),
        "errors": [why],
        "files": None,
        "wall_s": None,
    }


class Pool:
    """The workers of one rack run (one gateway per job) and what each sent back."""

    def __init__(self, specs: Sequence[str], jobs: Sequence[dict[str, Any]]) -> None:
        import execnet

        self.jobs = list(jobs)
        self.results: dict[int, dict[str, Any]] = {}
        self.group = execnet.Group(execmodel="main_thread_only")
        self._inbox: queue.Queue[tuple[int, Any]] = queue.Queue()
        self._channels: dict[int, Any] = {}
        self._let_go: list[Any] = []  # gateways exited as their result came: reaped at close
        source = worker_source()
        for i, (spec, job) in enumerate(zip(specs, jobs, strict=True)):
            try:
                gateway = self.group.makegateway(main_thread_spec(spec))
                channel = gateway.remote_exec(source)
                channel.send(job)
            except Exception as exc:  # an ssh host down, a python missing there
                self.results[i] = lost_result(
                    job, f"worker {spec!r} did not start: {type(exc).__name__}: {exc}",
                    EXIT_INTERNAL,
                )  # fmt: skip
                continue
            channel.setcallback(lambda item, i=i: self._inbox.put((i, item)), endmarker=_CLOSED)
            self._channels[i] = channel

    def _stop_all(self) -> None:
        """Pass the rack's Ctrl-C on to every worker still running."""
        for i, channel in self._channels.items():
            if i not in self.results:
                with contextlib.suppress(Exception):  # its channel closed as it finished
                    channel.send(STOP)

    def _heard(self, i: int, item: Any, on_result: Callable[[int, dict[str, Any]], None]) -> None:
        if i in self.results:
            return  # the channel's end after its result
        if item is _CLOSED:
            item = lost_result(
                self.jobs[i], "the worker ended without a result (it crashed or was killed)",
                EXIT_INTERNAL,
            )  # fmt: skip
        self.results[i] = item
        with contextlib.suppress(Exception):  # its work is done: let its process go now
            gateway = self._channels[i].gateway
            gateway.exit()
            self._let_go.append(gateway)
        on_result(i, item)

    def wait(
        self, on_result: Callable[[int, dict[str, Any]], None], grace: float = STOP_GRACE
    ) -> list[dict[str, Any]]:
        """Every job's result, in job order, ``on_result(index, result)`` as each comes;
        the rack's Ctrl-C (the interrupt guard's record) stops every worker."""
        for i in sorted(self.results):
            on_result(i, self.results[i])
        stopped_at: float | None = None
        while len(self.results) < len(self.jobs):
            if GUARD.requested and stopped_at is None:
                stopped_at = time.monotonic()
                self._stop_all()
            if stopped_at is not None and time.monotonic() - stopped_at > grace:
                break
            try:
                i, item = self._inbox.get(timeout=_POLL)
            except queue.Empty:
                continue
            self._heard(i, item, on_result)
        for i, job in enumerate(self.jobs):
            if i not in self.results:
                self.results[i] = lost_result(
                    job, f"the worker did not stop within {grace:g} s of Ctrl-C",
                    EXIT_INCOMPLETE,
                )  # fmt: skip
                on_result(i, self.results[i])
        return [self.results[i] for i in range(len(self.jobs))]

    def close(self) -> None:
        """End every worker process (each has sent its result, or is given up on), and wait
        for the local ones let go early: an exited gateway leaves its group, so terminate()
        no longer waits for its process, which stayed a zombie of the rack's process (found
        by tests/harness/test_device.py after the rack tests, in one process)."""
        self.group.terminate(timeout=5.0)
        for gateway in self._let_go:
            _reap(gateway)


def _reap(gateway: Any, timeout: float = 5.0) -> None:
    """Wait for a ``popen`` worker's process (killed if it will not end); other kinds of
    gateway have no local process."""
    import subprocess

    popen = getattr(getattr(gateway, "_io", None), "popen", None)
    if popen is None:
        return
    try:
        popen.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(OSError):
            popen.kill()
        with contextlib.suppress(OSError, subprocess.TimeoutExpired):
            popen.wait(timeout=timeout)
