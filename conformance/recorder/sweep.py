"""The recorder tolerance sweep (issue 24, item 3): where does the recorder under test stop
coping with a slow sensor, and is that inside what the standard lets a sensor take?

Two sweeps, each a series of short jobs (``0M!``, then ``0D0!`` after the service request)
on one played sensor, as the Arduino SDI-12 library's timing test sketch does:

- ``reply``: the sensor starts every reply later and later. Extra delay beyond the reference
  sensor's 9.00 ms: 0, 5, 10, ..., 100 ms, plus the standard's own limit as a step of its
  own (6.40 ms extra: a reply starting at 15.40 ms).
- ``wake``: after a break the sensor needs longer and longer before it hears a start bit at
  all: 0, 5, 10, ..., 150 ms after the break's end (past 100 ms, so the sweep shows where a
  conforming recorder stops too).

What a recorder must cope with (the decision behind ``limit_ms`` and ``flag``):

- **reply**: a sensor's first response start bit may come up to 15.0 ms (+0.40 ms,
  R-7.0-01) after the command's last stop bit (R-7.0-10). Only "no reply" triggers a retry
  (R-7.2-05), and a reply that starts within 15.40 ms is a reply: a recorder that takes it
  as silence, retries into it and never gets the data does not implement the retry rules for
  a conforming sensor. So it must get the data at every reply start up to **15.40 ms**; how
  (first try, a retry, a new break) is its own business.
- **wake**: a sensor can detect a command's start bit within 100 ms of detecting the break
  (R-7.0-07). It detects the break no later than the break's end, so a conforming sensor
  hears start bits at the latest 100 ms after the break's end. The standard provides for
  exactly that sensor: one retry must start more than 100 ms after the end of the break
  (R-7.2-03), and retries themselves come 16.67-87 ms after the command (R-7.2-02). So a
  recorder must get the data from a sensor that needs up to **100 ms** after the break.

Everything past those limits is beyond the standard (a recorder MAY cope, the way the
golden recorder copes with a reply starting at 19 ms): the sweep is informational. It never
changes a requirement verdict; it only says where the recorder gave up and, when that is
inside the limit, flags it with the requirement IDs above.

Whether a step coped is decided from what was observed (:func:`judge_step`, a pure function
over the step's transcript and the recorder's own account): the values of the sensor's valid
data replies on the wire must be the values it holds, and where the recorder reported what it
logged, that must be those values too.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..emulator.behaviour import REPLY_DELAY
from ..judges.recorder.logged import same_values
from ..judges.recorder.measurements import observed_measurements
from ..judges.recorder.retries import STANDBY
from ..links.base import LinkError
from ..protocol.timing import RESPONSE_START_MAX, TOLERANCE, WAKE_LIMIT
from ..recorder_jobs import RecorderOutput, Request, Task
from ..transcript import Event, EventKind
from ..view.segments import Transmission, read_view
from .drivers import RecorderSetupError
from .played import SensorSpec
from .scenarios import Scenario

REPLY = "reply"
WAKE = "wake"
KINDS = (REPLY, WAKE)
#: What a step asks the recorder: one measurement and its data, on one sensor at "0".
COMMAND = "0M!"
ADDRESS = "0"
MEASUREMENT = "M"

#: The reference sensor's reply start (ms after the command's last stop bit).
NORMAL_REPLY_MS = REPLY_DELAY * 1e3
#: R-7.0-10 (+0.40 ms, R-7.0-01): the latest reply start a recorder must wait for.
REPLY_LIMIT_MS = round((RESPONSE_START_MAX + TOLERANCE) * 1e3, 3)
#: R-7.0-07 with R-7.2-03: how long after the break a sensor may need to hear a command.
WAKE_LIMIT_MS = round(WAKE_LIMIT * 1e3, 3)

REPLY_STEPS_MS: tuple[float, ...] = tuple(
    sorted({*range(0, 101, 5), round(REPLY_LIMIT_MS - NORMAL_REPLY_MS, 3)})
)
WAKE_STEPS_MS: tuple[float, ...] = tuple(float(ms) for ms in range(0, 151, 5))

FIRST_TRY = "first try"
AFTER_RETRY = "after a retry"
AFTER_BREAK = "after a new break"


@dataclass(frozen=True)
class SweepKind:
    """One sweep's fixed facts: its steps, how a step's extra becomes the effective time,
    the standard's limit on that time and the requirements that set it."""

    name: str
    steps_ms: tuple[float, ...]
    normal_ms: float  # the effective time with no extra
    limit_ms: float
    requirements: tuple[str, ...]
    measures: str  # what effective_ms is, for the report

    def effective_ms(self, extra_ms: float) -> float:
        return round(self.normal_ms + extra_ms, 3)

    def spec(self, extra_ms: float) -> SensorSpec:
        extra = extra_ms / 1e3
        if self.name == REPLY:
            return SensorSpec(ADDRESS, reply_extra=extra)
        return SensorSpec(ADDRESS, wake_extra=extra)

    def flag(self, gave_up_ms: float) -> str:
        """The text for a recorder that gave up at ``gave_up_ms``, inside the limit."""
        if self.name == REPLY:
            return (
                f"gave up on a reply starting {gave_up_ms:.2f} ms after the command, inside the "
                f"{self.limit_ms:.2f} ms a sensor may take (R-7.0-10): a reply that starts in "
                "time is no silence to retry on (R-7.2-05)"
            )
        return (
            f"gave up on a sensor that hears commands {gave_up_ms:.2f} ms after the break, "
            f"inside the {self.limit_ms:.0f} ms a sensor may need (R-7.0-07): a retry more than "
            "100 ms after the break would have reached it (R-7.2-03)"
        )


SWEEP_KINDS: dict[str, SweepKind] = {
    REPLY: SweepKind(
        REPLY,
        REPLY_STEPS_MS,
        NORMAL_REPLY_MS,
        REPLY_LIMIT_MS,
        ("R-7.0-10", "R-7.2-05"),
        "reply start after the command's last stop bit",
    ),
    WAKE: SweepKind(
        WAKE,
        WAKE_STEPS_MS,
        0.0,
        WAKE_LIMIT_MS,
        ("R-7.0-07", "R-7.2-03"),
        "time after the break's end before the sensor hears a start bit",
    ),
}


def parse_kinds(text: str | None) -> tuple[str, ...]:
    """``--sweep`` as given ("reply", "wake", "reply,wake"; "" or None: none) -> the kinds,
    in the order given, once each. Raises ValueError naming the unknown ones."""
    names = [n.strip() for n in (text or "").split(",") if n.strip()]
    unknown = [n for n in names if n not in SWEEP_KINDS]
    if unknown:
        raise ValueError(
            f"--sweep takes {', '.join(KINDS)} or both comma-separated (got {', '.join(unknown)})"
        )
    return tuple(dict.fromkeys(names))


@dataclass(frozen=True)
class StepOutcome:
    """What one step showed: whether the recorder got valid data, and how."""

    coped: bool
    how: str | None  # FIRST_TRY, AFTER_RETRY, AFTER_BREAK; None when it did not cope
    evidence: str
    #: the first reply's start after its command (ms), as seen on the wire; None: no reply
    observed_reply_ms: float | None = None


def _tries(transmissions: Sequence[Transmission], view: Any) -> list[tuple[str, int, int]]:
    """Consecutive transmissions of one command text: (text, tries, sequences). A try that
    follows a break, or more than 100 ms of marking (the sensor is then in standby,
    R-7.0-15), starts a new sequence; otherwise it is a retry (section 7.2)."""
    out: list[tuple[str, int, int]] = []
    last: Transmission | None = None
    for t in transmissions:
        if last is not None and last.text == t.text:
            before = view.previous_activity(t)
            quiet = t.first_char - (last.end if before is None else before)
            text, tries, sequences = out[-1]
            new_sequence = t.break_event is not None or quiet > STANDBY
            out[-1] = (text, tries + 1, sequences + new_sequence)
        else:
            out.append((t.text, 1, 1))
        last = t
    return out


def _first_reply_ms(
    events: Sequence[Event], is_recorder: Callable[[Event], bool], first: Transmission | None
) -> float | None:
    """When the sensor's first character after the first ``command`` began (ms after that
    command's last stop bit), whoever's turn the recorder thought it was: the reply start the
    sensor actually gave, even if the recorder had retried by then. None: it never spoke."""
    if first is None:
        return None
    starts = [
        e.start
        for e in events
        if e.kind is EventKind.CHAR and not is_recorder(e) and e.start >= first.end
    ]
    return round((min(starts) - first.end) * 1e3, 3) if starts else None


def judge_step(
    events: Sequence[Event],
    is_recorder: Callable[[Event], bool],
    output: RecorderOutput | None,
    expected: Sequence[str],
    *,
    command: str = COMMAND,
    uncertainty: float = 0.0,
) -> StepOutcome:
    """Whether the recorder coped with one step, from the step's transcript and its account.

    Coped: some measurement ``command`` it started is followed by valid data replies whose
    values are the ``expected`` ones (the judges' own validity rules, not the recorder's),
    and, if it reported what it logged, it logged those values. How: the worst of the job's
    commands: each sent once (first try), some sent again without a break within the sensor's
    wake time (after a retry), or some sent again after a break (after a new break).
    """
    view = read_view(list(events), is_recorder)
    sent = [t for t in view.transmissions if t.is_command]
    groups = _tries(sent, view)
    said = "; ".join(
        f"{text} sent {tries}x" + (f" in {seq} sequences" if seq > 1 else "")
        for text, tries, seq in groups
    )
    observed = _first_reply_ms(
        events, is_recorder, next((t for t in sent if t.text == command), None)
    )
    taken = [m for m in observed_measurements(view, uncertainty) if m.start.text == command]
    on_wire = any(same_values(expected, m.values()) for m in taken)
    logged = output.reported_logged() if output is not None else None
    logged_ok = None if logged is None else same_values(expected, logged.get(command, []))
    if not on_wire:
        why = (
            "no valid data on the wire"
            if not taken or not any(m.data for m in taken)
            else ("the data on the wire are not the sensor's values")
        )
        return StepOutcome(False, None, f"{why} ({said or 'nothing sent'})", observed)
    if logged_ok is False:
        return StepOutcome(
            False, None, f"valid data on the wire, but logged values differ ({said})", observed
        )
    if any(seq > 1 for _, _, seq in groups):
        how = AFTER_BREAK
    elif any(tries > 1 for _, tries, _ in groups):
        how = AFTER_RETRY
    else:
        how = FIRST_TRY
    source = "wire and log" if logged_ok else "wire only (no log reported)"
    return StepOutcome(True, how, f"{len(expected)} value(s) from the {source}; {said}", observed)


@dataclass
class SweepStep:
    extra_ms: float
    effective_ms: float
    outcome: StepOutcome

    def to_json(self) -> dict[str, Any]:
        return {
            "extra_ms": self.extra_ms,
            "effective_ms": self.effective_ms,
            "coped": self.outcome.coped,
            "how": self.outcome.how,
            "evidence": self.outcome.evidence,
            "observed_reply_ms": self.outcome.observed_reply_ms,
        }


@dataclass
class Sweep:
    """One sweep's steps and what they add up to."""

    kind: SweepKind
    steps: list[SweepStep] = field(default_factory=list)
    #: why the sweep ended before its last step (the recorder could not be made to act)
    stopped: str | None = None

    @property
    def copes_up_to_ms(self) -> float | None:
        """The highest effective time up to which every step coped (None: not even the
        first one)."""
        best = None
        for step in self.steps:
            if not step.outcome.coped:
                break
            best = step.effective_ms
        return best

    @property
    def first_failure_ms(self) -> float | None:
        return next((s.effective_ms for s in self.steps if not s.outcome.coped), None)

    @property
    def flag(self) -> str | None:
        """Text naming the requirement when the recorder gave up inside the limit."""
        inside = [s for s in self.steps if s.effective_ms <= self.kind.limit_ms + 1e-9]
        failed = next((s for s in inside if not s.outcome.coped), None)
        return None if failed is None else self.kind.flag(failed.effective_ms)

    def to_json(self) -> dict[str, Any]:
        k = self.kind
        return {
            "kind": k.name,
            "unit": "ms",
            "measures": k.measures,
            "normal_ms": k.normal_ms,
            "limit_ms": k.limit_ms,
            "requirements": list(k.requirements),
            "steps": [s.to_json() for s in self.steps],
            "copes_up_to_ms": self.copes_up_to_ms,
            "first_failure_ms": self.first_failure_ms,
            "flag": self.flag,
            "stopped": self.stopped,
        }


def sweep_scenario(kind: SweepKind, extra_ms: float) -> Scenario:
    """The step's scenario: one sensor, slowed by ``extra_ms``, and the short job."""
    return Scenario(
        f"sweep-{kind.name}-{extra_ms:g}ms",
        f"tolerance sweep ({kind.name}, {extra_ms:g} ms extra)",
        (kind.spec(extra_ms),),
        Request(Task.MEASURE, (COMMAND,)),
    )


def run_sweeps(session: Any, kinds: Iterable[str]) -> list[Sweep]:
    """Run each named sweep on ``session`` (a :class:`~.session.RecorderSession`), step by
    step, one job per step. A recorder that cannot be made to act, or a link that fails
    (a ``replay:`` of a run that had no such step), stops that sweep with the reason in
    ``stopped``: the setup is broken, not the recorder, so no step is held against it."""
    sweeps: list[Sweep] = []
    for name in kinds:
        kind = SWEEP_KINDS[name]
        sweep = Sweep(kind)
        sweeps.append(sweep)
        for extra in kind.steps_ms:
            try:
                run = session.run_scenario(sweep_scenario(kind, extra))
            except RecorderSetupError as exc:
                sweep.stopped = str(exc)
                break
            except LinkError as exc:  # a replayed run without this step, a link gone
                sweep.stopped = f"{type(exc).__name__}: {exc}"
                break
            outcome = judge_step(
                run.events,
                session.is_recorder,
                run.output,
                run.expected_values(ADDRESS, MEASUREMENT),
                uncertainty=session.uncertainty,
            )
            if run.error:
                outcome = StepOutcome(
                    False,
                    None,
                    f"{outcome.evidence}; the driver failed: {run.error}",
                    outcome.observed_reply_ms,
                )
            sweep.steps.append(SweepStep(extra, kind.effective_ms(extra), outcome))
    return sweeps
