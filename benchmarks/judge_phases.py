"""Where a passive judgement's memory goes, phase by phase: what is resident once the
recording is loaded and read (decode, view, the pre-scans of the sensors on the bus), and for
each run of the passive cases (one per sensor of a bus, then the recorder's) the resident
memory before it, its own peak and what it leaves behind, with its CPU; the loading's own
steps too (the decode, the bus pass that checks the recording holds SDI-12 traffic), each
with its own peak.

    MALLOC_ARENA_MAX=1 python benchmarks/judge_phases.py CAPTURE REPORTS [--json]

``benchmarks/capture_decode.py --judge`` gives one figure, the whole judgement's peak; issue
22 needs to know which phase grows with the capture's length (a windowed judge drops the
events and their view per window: this says what each phase holds before and after). A run's
own peak is the high-water mark (``VmHWM``) since Linux was told to reset it
(``/proc/self/clear_refs``, "5") just before the run, so each run's figure is its own, not
the highest of the runs before it. Linux only; the judgement is this process's (run it in a
fresh one: it reads this process's own memory). The runs are found by wrapping
:func:`conformance.commands.passive._run_role`, the one call each run goes through; nothing
else of the judgement changes.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from typing import Any

KB_PER_MB = 1024


def status_mb(field: str) -> float:
    """``field`` (``VmRSS``, ``VmHWM``) of this process's ``/proc/self/status``, in MB."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / KB_PER_MB
    raise KeyError(field)


def reset_peak() -> None:
    """Start a new high-water mark (``VmHWM`` := ``VmRSS``): Linux's clear_refs value 5."""
    with open("/proc/self/clear_refs", "w") as refs:
        refs.write("5")


def measured_step(
    phases: list[dict[str, Any]], module: Any, name: str, label: str
) -> Callable[[], None]:
    """Wrap ``module.name`` (a step of the loading: the decode, the bus pass) so each call
    appends its figures to ``phases``: the resident memory before and after it and its own
    peak (the high-water mark reset just before it); gives the function that undoes it."""
    original = getattr(module, name)

    def step(*args, **kwargs):  # type: ignore[no-untyped-def]
        before = status_mb("VmRSS")
        reset_peak()
        cpu = time.process_time()
        result = original(*args, **kwargs)
        phases.append(
            {
                "phase": label,
                "rss_before_mb": before,
                "peak_mb": status_mb("VmHWM"),
                "rss_after_mb": status_mb("VmRSS"),
                "cpu_s": round(time.process_time() - cpu, 3),
            }
        )
        return result

    setattr(module, name, step)
    return lambda: setattr(module, name, original)


def measured_runs(phases: list[dict[str, Any]]) -> Callable[[], None]:
    """Wrap the passive judgement's per-run call so each run appends its figures to
    ``phases`` (the first one also the loading's); gives the function that undoes it."""
    from conformance.commands import passive

    original = passive._run_role

    def run_role(job, port, args, console):  # type: ignore[no-untyped-def]
        before = status_mb("VmRSS")
        if not any(p_["phase"].startswith("run ") for p_ in phases):
            # the decode, the bus pass and the pre-scans: everything before a run (its peak
            # the highest since the last step measured, or since the process began)
            peak = max([status_mb("VmHWM")] + [p_["peak_mb"] for p_ in phases])
            phases.append({"phase": "loaded", "rss_mb": before, "peak_mb": peak})
        reset_peak()
        cpu = time.process_time()
        result = original(job, port, args, console)
        phases.append(
            {
                "phase": f"run {job.label}",
                "rss_before_mb": before,
                "peak_mb": status_mb("VmHWM"),
                "rss_after_mb": status_mb("VmRSS"),
                "cpu_s": round(time.process_time() - cpu, 3),
            }
        )
        return result

    passive._run_role = run_role

    def undo() -> None:
        passive._run_role = original

    return undo


def judge(capture: str, reports: str) -> tuple[int, list[dict[str, Any]], float]:
    """``sdi12-conform judge CAPTURE --report-dir REPORTS`` in this process: its exit code,
    the phases' figures and the whole judgement's CPU (s)."""
    import contextlib
    import io

    from conformance.cli import main
    from conformance.commands import passive
    from conformance.offline import judge as judge_module

    phases: list[dict[str, Any]] = []
    undos = [
        measured_step(phases, judge_module, "decode", "decode"),
        measured_step(phases, passive, "no_traffic", "bus pass"),
        measured_runs(phases),
    ]
    cpu = time.process_time()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            code = main(["judge", capture, "--report-dir", reports])
    except SystemExit as exc:
        code = int(exc.code or 0)
    finally:
        for undo in undos:
            undo()
    return code, phases, time.process_time() - cpu


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("capture")
    p.add_argument("reports", help="the report folder (written)")
    p.add_argument("--json", action="store_true", help="one JSON document instead of lines")
    args = p.parse_args(argv)
    code, phases, cpu = judge(args.capture, args.reports)
    peak = max([p_["peak_mb"] for p_ in phases] + [status_mb("VmHWM")], default=status_mb("VmHWM"))
    if args.json:
        print(json.dumps({"code": code, "cpu_s": cpu, "peak_mb": peak, "phases": phases}))
        return 0
    for ph in phases:
        if ph["phase"] == "loaded":
            print(f"loaded            rss {ph['rss_mb']:7.1f} MB  peak so far {ph['peak_mb']:7.1f}")
            continue
        print(
            f"{ph['phase']:<17} rss {ph['rss_before_mb']:7.1f} -> {ph['rss_after_mb']:7.1f} MB"
            f"  own peak {ph['peak_mb']:7.1f}  cpu {ph['cpu_s']:.2f} s"
        )
    print(f"exit {code}, whole peak {peak:.1f} MB, cpu {cpu:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
