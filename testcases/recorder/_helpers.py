"""What the recorder cases share: picking scenarios and attaching their transcripts."""

from __future__ import annotations

from conformance import preconditions as precondition
from conformance.case import Case
from conformance.judges.recorder.logged import LogReport
from conformance.recorder.scenario_runner import RecorderSession
from conformance.recorder.scenarios import SCENARIOS
from conformance.view.segments import TranscriptView


def line_of(
    recorder: RecorderSession, case: Case, *names: str, whole_run: bool = False
) -> TranscriptView | None:
    """Run the scenarios (the applicable ones), attach their wire logs, and read them.

    None (with N/A findings) when none applies to the recorder's claimed version. A scenario
    the recorder could not be made to act on is a hole in the certificate: INCONCLUSIVE.
    ``whole_run``: the rule is about every transmission the recorder made. A job cut at its
    budget (recorder.job_time) holds all it sent, so such a rule judges it in full; a rule
    about the job itself still cannot PASS on a job that never ended.
    """
    chosen = [n for n in names if recorder.applies(n)]
    if not chosen:
        case.requires(
            "recorder",
            precondition.Unmet(
                "recorder", "these scenarios need a recorder claiming SDI-12 v1.4", absent=True
            ),
        )
        return None
    errors = []
    for name in chosen:
        run = recorder.run(name)
        label = f"scenario {name}: {SCENARIOS[name].describe()}"
        if run.timed_out is not None:
            label += f" [cut: {run.error}]"
        case.evidence(label, run.events)
        if run.timed_out is not None and whole_run:
            continue  # every transmission it made is in the slice
        if run.error:
            errors.append(f"scenario {name}: {run.error}")
    case.requires("recorder", precondition.acted(errors))
    return recorder.view(*chosen)


def logged(recorder: RecorderSession, name: str) -> dict[str, list[str]] | None:
    """What the recorder says it logged in a scenario (None when it says nothing)."""
    out = recorder.run(name).output
    return out.logged or None


def relayed(recorder: RecorderSession, name: str) -> dict[str, str] | None:
    out = recorder.run(name).output
    return out.relayed or None


def log_reports(recorder: RecorderSession, names: list[str]) -> list[LogReport]:
    """What the recorder says it logged in each scenario, in ``names`` order (the parts of
    :func:`line_of`'s view)."""
    reports = []
    for name in names:
        run = recorder.run(name)
        out = run.output
        reports.append(LogReport(name, out.reported_logged(), out.log_problem, bool(run.error)))
    return reports
