"""The exploration's hypothesis state machine: the rules that draw the stimuli and the steps
that send them and check the invariants (:mod:`.exploration` holds what a run keeps, and
:func:`~.exploration.explore` loads this module, hypothesis with it, only when it runs)."""

from __future__ import annotations

from typing import ClassVar

from hypothesis import HealthCheck, Phase, seed, settings
from hypothesis import strategies as st
from hypothesis.core import failure_exceptions_to_catch, skip_exceptions_to_reraise
from hypothesis.stateful import RuleBasedStateMachine, rule, run_state_machine_as_test

from ..judges.exploration import Observation, judge
from ..protocol.commands import ADDRESS_CHARS
from ..protocol.responses import split_line
from ..tool_recorder.records import Exchange
from ..transcript import escape
from .address_change import AddressChanger
from .exploration_record import (
    FOREIGN_FORMS,
    MAX_WAIT_OUT,
    OWN,
    SEED,
    Exploration,
    InvariantBroken,
    harmless,
    moved_by_malformed,
)
from .session import SensorSession


def junk_strategy() -> st.SearchStrategy[str]:
    """The malformed commands' strategy (:data:`.exploration.JUNK`)."""
    return st.text(
        alphabet=st.sampled_from("MDCRIVXAB0123456789+-._#"), min_size=1, max_size=6
    ).filter(harmless)


class _Explorer(RuleBasedStateMachine):
    """The stimuli and records behind the rules of :func:`machine_class`'s class (the rules
    themselves are made per run: their strategies depend on the sensor's address and on the
    module's JUNK at the time of the run, handed in as ``junk``)."""

    sensor: ClassVar[SensorSession]
    record: ClassVar[Exploration]
    marking: ClassVar[float | None]  # the marking foreign commands go out with

    def __init__(self) -> None:
        super().__init__()
        self.address = self.sensor.address
        self.trail: list[str] = []
        self.last_d0: str | None = None  # D0 reply since the last measurement command
        self.sensor.master.send_break()

    def _observe(self, observation: Observation) -> None:
        """Record one checked step and end the example if the judges find it broke an
        invariant. The failing sequence is kept at the first breach: hypothesis replays a
        failing example to confirm it, and a real device, whose state moved on, may then
        behave otherwise (hypothesis calls that flaky); the first observation stands."""
        self.record.observations.append(observation)
        breach = judge(observation).breach
        if breach is None:
            return
        if not self.record.breached:
            self.record.breached = True
            self.record.failing_sequence = list(self.trail)
        raise InvariantBroken(breach.requirement, breach.message)

    def _wait_out(self, ex: Exchange) -> None:
        """A concurrent measurement runs on after its reply: wait its announced time, so
        anything it sends then (a faulty service request) lands in a pause of its own and
        is judged by the concurrent cases, not taken for the reply to the next step."""
        body, _ = split_line(ex.reply_text)
        ttt = body[1:4]
        if ttt.isdigit() and int(ttt) > 0:
            heard = self.sensor.listen(min(int(ttt), MAX_WAIT_OUT) + 0.05)
            self._note(f"wait {ttt} s" + (" (heard something)" if heard else ""))

    def _note(self, text: str) -> None:
        self.trail.append(text)
        self.record.steps += 1

    def _send(self, code: str) -> Exchange:
        ex = self.sensor.master.transact(f"{self.address}{code}!")
        self.record.exchanges.append(ex)
        self._note(f"{escape(ex.text)} -> '{escape(ex.reply_text)}'")
        return ex

    def _own(self, code: str) -> None:
        """A command to the sensor's own address; its reply's framing, CRC and D0 repeat
        are observed (only an answered one: silence is judged by the other cases)."""
        ex = self._send(code)
        if code[:1] in ("M", "C", "V", "H"):
            self.last_d0 = None  # a new measurement may change the data
        if not ex.answered:
            return
        if code in ("C", "CC"):
            self._wait_out(ex)
        self._observe_framing(ex)
        if code.startswith("D"):
            self._observe(Observation("crc", ex.text, ex.reply_text))
        if code == "D0":
            previous = self.last_d0
            self._observe(Observation("repeat", ex.text, ex.reply_text, previous=previous))
            self.last_d0 = ex.reply_text

    def _foreign(self, other: str, code: str) -> None:
        """A command to another address, sent the way the sensor was shown to hear."""
        ex = self.sensor.master.raw(f"{other}{code}!", break_first=True, marking=self.marking)
        self.record.exchanges.append(ex)
        self._note(f"{escape(ex.text)} (foreign) -> '{escape(ex.reply_text)}'")
        marked = self.marking is not None
        self._observe(
            Observation(
                "foreign",
                ex.text,
                ex.reply_text,
                other,
                answered=ex.answered,
                marked=marked,
                collided=ex.maybe_collided,
            )
        )

    def _malformed(self, junk: str) -> None:
        """A malformed command: silence or any well-framed reply is fine (decision A12)."""
        ex = self.sensor.master.raw(f"{self.address}{junk}!", break_first=None)
        self.record.exchanges.append(ex)
        self._note(f"{escape(ex.text)} (malformed?) -> '{escape(ex.reply_text)}'")
        if ex.answered:
            moved = moved_by_malformed(junk, ex.reply_text, self.address)
            if moved is not None:
                self._follow_address_change(moved)
                return
            self._observe_framing(ex)
            # junk can spell a real command ("M", or "-7!0MC" ending in one): whatever
            # the sensor accepted may have started a measurement
            self.last_d0 = None

    def _follow_address_change(self, moved: str) -> None:
        """The sensor read the malformed command as ``aAb!`` and now answers at
        ``moved``: informative under decision A12, not a reply from the wrong address;
        put it back, so every later step talks to the address it has."""
        changer = AddressChanger(self.sensor.master, self.address)
        changer.current = moved
        changer.tried.append(moved)
        note = self.sensor.restore(changer)
        self.record.exchanges += changer.exchanges
        self._note(f"taken as a change to address '{moved}' (decision A12); {note}")

    def _observe_framing(self, ex: Exchange) -> None:
        self._observe(Observation("framing", ex.text, ex.reply_text, self.address))

    def step(self, name: str, arguments: dict[str, object]) -> None:
        """Send one step drawn for the rule ``name`` (:func:`_with_rules`)."""
        getattr(self, "_" + name)(**arguments)

    def _own_command(self, code: str) -> None:
        self._own(code)

    def _read_data(self, index: str) -> None:
        self._own(f"D{index}")

    def _foreign_command(self, other: str, code: str) -> None:
        self._foreign(other, code)

    def _malformed_command(self, junk: str) -> None:
        self._malformed(junk)

    def _brk(self) -> None:
        self.sensor.master.send_break()
        self._note("break")

    def _pause(self, seconds: float) -> None:
        self.sensor.listen(seconds)
        self._note(f"pause {seconds * 1e3:.0f} ms")

    def teardown(self) -> None:
        self.record.log.append(" ; ".join(self.trail))
        if not self.record.breached:  # after a break, the sequence that broke it stays
            self.record.failing_sequence = list(self.trail)


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


def foreign_addresses(sensor: SensorSession) -> list[str]:
    """The addresses the foreign commands go to (a strategy of the rules: part of a plan's
    key, :func:`plan_for`)."""
    foreign = [a for a in "9zy" if a != sensor.address]
    if sensor.shared:  # never an address another sensor of the line answers at
        spare = "9zyxwv" + ADDRESS_CHARS[::-1]
        foreign = [
            a for a in dict.fromkeys(spare) if a != sensor.address and a not in sensor.others
        ]
        foreign = foreign[:3]
    return foreign


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


#: one step of a plan: a rule's name and the arguments drawn for it
Step = tuple[str, dict[str, object]]
#: what a derandomised run draws: for each example hypothesis runs, its steps in order
Plan = tuple[tuple[Step, ...], ...]


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
    """Send ``plan`` with ``machine`` as hypothesis sends it (:func:`run_machine`): each
    example a new machine, its steps, its teardown (also after a step raised). The first
    example whose machine or step raises a failure ends the run, and, as hypothesis
    replays a failing example once to report it, it runs again from a new machine up to
    the step that raised (the replay's choices end there), and that step's exception, or
    the first one where the replay raised none, goes out."""
    for example in plan:
        failed = _run_example(machine, example)
        if failed is not None:
            index, first = failed
            again = _run_example(machine, example[: index + 1])
            raise (again[1] if again is not None else first)


def _run_example(
    machine: type[RuleBasedStateMachine], steps: tuple[Step, ...]
) -> tuple[int, BaseException] | None:
    """One example of :func:`run_plan`: None, or the index of the step that raised a failure
    (-1: the machine's making) and the exception. Hypothesis's own classes of exceptions:
    a skip and anything not a failure (Ctrl-C) go straight out, after the teardown."""
    failures, skips = failure_exceptions_to_catch(), skip_exceptions_to_reraise()
    try:
        made = machine()
    except skips:
        raise
    except failures as exc:
        return -1, exc
    index = 0  # the step being sent
    try:
        for name, arguments in steps:
            made.step(name, arguments)
            index += 1
    except skips:
        raise
    except failures as exc:
        return index, exc
    finally:
        made.teardown()
    return None


def release(machine: type[RuleBasedStateMachine]) -> None:
    """Let go of the run a machine class of :func:`machine_class` was made for, once it has
    run. Hypothesis keeps every state machine class it ran for the rest of the process
    (``RuleBasedStateMachine._setup_state_per_class``, a plain dict), and the class held its
    run's sensor session, hence the run's link, transcript and views: a process making run
    after run (a fault matrix's worker, a test session) kept every one of them, about 650,000
    objects (some 100 MB against wrong-crc) a run, which its collections then walked again
    and again. The class's own attributes are dropped (nothing reads them after the run) and
    hypothesis's entry for it, where this hypothesis keeps one."""
    for name in ("sensor", "record", "marking"):
        if name in vars(machine):
            delattr(machine, name)
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
