"""The exploration's hypothesis state machine: the rules that draw the stimuli and the steps
that send them and check the invariants (:mod:`.exploration` holds what a run keeps, and
:func:`~.exploration.explore` loads this module, hypothesis with it, only when it runs)."""

from __future__ import annotations

from typing import ClassVar

from hypothesis import HealthCheck, Phase, seed, settings
from hypothesis import strategies as st
from hypothesis.core import failure_exceptions_to_catch, skip_exceptions_to_reraise
from hypothesis.stateful import RuleBasedStateMachine, rule, run_state_machine_as_test

from .exploration_record import FOREIGN_FORMS, OWN, SEED, Exploration, harmless
from .exploration_steps import (
    ExplorerSteps,
    Plan,
    Step,
    foreign_addresses,
    release_attributes,
)
from .exploration_steps import run_plan as send_plan
from .session import SensorSession

__all__ = ["foreign_addresses", "machine_class", "plan_for", "release", "run_machine", "run_plan"]


def junk_strategy() -> st.SearchStrategy[str]:
    """The malformed commands' strategy (:data:`.exploration.JUNK`)."""
    return st.text(
        alphabet=st.sampled_from("MDCRIVXAB0123456789+-._#"), min_size=1, max_size=6
    ).filter(harmless)


class _Explorer(ExplorerSteps, RuleBasedStateMachine):
    """The exploration's steps (:class:`~.exploration_steps.ExplorerSteps`) as hypothesis's
    state machine: the base of :func:`machine_class`'s class, whose rules hypothesis draws."""


def machine_class(
    sensor: SensorSession,
    record: Exploration,
    marking: float | None,
    junk: st.SearchStrategy[str],
) -> type[RuleBasedStateMachine]:
    """The state machine class for one run (its rules: :func:`_with_rules`)."""
    machine = _with_rules(_Explorer, foreign_addresses(sensor), junk)
    machine.sensor = sensor
    machine.record = record
    machine.marking = marking
    return seed(SEED)(machine)


def _with_rules(
    base: type[RuleBasedStateMachine], foreign: list[str], junk: st.SearchStrategy[str]
) -> type[RuleBasedStateMachine]:
    """``base`` with the exploration's rules, each handing its drawn arguments to
    ``base.step``: the one place of their names and strategies, so the machine that sends
    (:class:`_Explorer`) and the one that only writes the draws down (:class:`_Recorder`)
    draw alike. Hypothesis orders rules by name and draws by strategy, so the names and
    strategies here are the exploration's stimuli: keep them."""

    class SensorMachine(base):  # type: ignore[valid-type,misc]
        @rule(code=st.sampled_from(OWN))
        def own_command(self, code: str) -> None:
            self.step("own_command", {"code": code})

        @rule(index=st.sampled_from(("0", "0", "1")))
        def read_data(self, index: str) -> None:
            """D replies, the place where the CRC and buffer invariants bite."""
            self.step("read_data", {"index": index})

        @rule(other=st.sampled_from(foreign), code=st.sampled_from(FOREIGN_FORMS))
        def foreign_command(self, other: str, code: str) -> None:
            self.step("foreign_command", {"other": other, "code": code})

        @rule(junk=junk)
        def malformed_command(self, junk: str) -> None:
            self.step("malformed_command", {"junk": junk})

        @rule()
        def brk(self) -> None:
            self.step("brk", {})

        @rule(seconds=st.sampled_from((0.01, 0.05, 0.12, 0.25)))
        def pause(self, seconds: float) -> None:
            self.step("pause", {"seconds": seconds})

    return SensorMachine


class _Recorder(RuleBasedStateMachine):
    """A machine that sends nothing: each example it is made for, the steps drawn
    (:func:`plan_for`). Its rules are the exploration's (:func:`_with_rules`)."""

    plans: ClassVar[list[list[Step]]]

    def __init__(self) -> None:
        super().__init__()
        self.steps: list[Step] = []
        self.plans.append(self.steps)

    def step(self, name: str, arguments: dict[str, object]) -> None:
        self.steps.append((name, arguments))


#: the plans drawn in this process: key -> (the junk strategy it was drawn with, the plan)
_PLANS: dict[tuple[object, ...], tuple[object, Plan]] = {}


def plan_for(foreign: list[str], junk: st.SearchStrategy[str], examples: int, steps: int) -> Plan:
    """The steps a derandomised run of the exploration draws, drawn once a process for its
    rules' strategies and settings. Nothing drawn depends on the sensor: the rules have no
    preconditions, bundles or invariants, the strategies are fixed at the class, and the
    settings (derandomised, generate phase only, no database, no deadline, health checks
    off) leave hypothesis nothing else to read but whether an example raised, which only
    ends the run (:func:`run_plan`). The caller holds hypothesis's draws still
    (``no_local_constants``, ``no_database_key``)."""
    key = (SEED, examples, steps, tuple(foreign), OWN, FOREIGN_FORMS, id(junk))
    held = _PLANS.get(key)
    if held is not None and held[0] is junk:
        return held[1]
    recorder = seed(SEED)(_with_rules(_Recorder, foreign, junk))
    recorder.plans = []
    try:
        run_machine(recorder, examples, steps)
        plan = tuple(tuple(steps_) for steps_ in recorder.plans)
    finally:
        del recorder.plans
        release(recorder)
    _PLANS[key] = (junk, plan)
    return plan


def forget_plans() -> None:
    """Drop the plans drawn so far (tests that want hypothesis to draw again)."""
    _PLANS.clear()


def run_plan(machine: type[RuleBasedStateMachine], plan: Plan) -> None:
    """Send ``plan`` with ``machine`` as hypothesis sends it, with hypothesis's own classes of
    exceptions (:func:`.exploration_steps.run_plan`)."""
    send_plan(machine, plan, failure_exceptions_to_catch, skip_exceptions_to_reraise)


def release(machine: type[RuleBasedStateMachine]) -> None:
    """Let go of the run a machine class of :func:`machine_class` was made for, once it has
    run. Hypothesis keeps every state machine class it ran for the rest of the process
    (``RuleBasedStateMachine._setup_state_per_class``, a plain dict), and the class held its
    run's sensor session, hence the run's link, transcript and views: a process making run
    after run (a fault matrix's worker, a test session) kept every one of them, about 650,000
    objects (some 100 MB against wrong-crc) a run, which its collections then walked again
    and again. The class's own attributes are dropped (nothing reads them after the run) and
    hypothesis's entry for it, where this hypothesis keeps one."""
    release_attributes(machine)
    kept = getattr(RuleBasedStateMachine, "_setup_state_per_class", None)
    if isinstance(kept, dict):
        kept.pop(machine, None)


def run_machine(machine: type[RuleBasedStateMachine], examples: int, steps: int) -> None:
    run_state_machine_as_test(
        machine,
        settings=settings(
            max_examples=examples,
            stateful_step_count=steps,
            derandomize=True,
            database=None,
            deadline=None,
            phases=[Phase.generate],
            report_multiple_bugs=False,
            suppress_health_check=list(HealthCheck),
            print_blob=False,
        ),
    )
