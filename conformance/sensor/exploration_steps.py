"""The exploration's steps without hypothesis: what each drawn step sends and checks
(:class:`ExplorerSteps`), and the sending of a plan of drawn steps as hypothesis sends it
(:func:`run_plan`). Hypothesis is needed to draw a plan, not to send one: a plan stored by an
earlier process (:mod:`.exploration_plans`) is sent with none of hypothesis loaded, which saved
a ``--port sim`` process about 0.07 s of CPU for hypothesis's import and as much for its draws
(issue 22)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import ClassVar

from ..judges.exploration import Observation, judge
from ..judges.late_before import answered_late
from ..protocol.commands import ADDRESS_CHARS
from ..protocol.responses import split_line
from ..tool_recorder.records import Exchange
from ..transcript import escape
from .address_change import AddressChanger
from .exploration_record import (
    MAX_WAIT_OUT,
    Exploration,
    InvariantBroken,
    moved_by_malformed,
)
from .session import SensorSession

#: one step of a plan: a rule's name and the arguments drawn for it
Step = tuple[str, dict[str, object]]
#: what a derandomised run draws: for each example hypothesis runs, its steps in order
Plan = tuple[tuple[Step, ...], ...]

#: the rules' names (``exploration_machine._with_rules``): the steps a plan may hold
RULES = ("brk", "foreign_command", "malformed_command", "own_command", "pause", "read_data")

#: the commands (their first letter after the address) that start a measurement: aM!, aMC!,
#: aC!, aCC!, aV!, aHA!, aHB!, each of which may change what D0 reads
MEASURING = ("M", "C", "V", "H")


class ExplorerSteps:
    """The stimuli and records behind the exploration's rules: each step a rule draws is sent
    by :meth:`step`. Hypothesis's state machine (``exploration_machine._Explorer``) is this
    with hypothesis's base class; a stored plan is sent by this alone (:func:`plain_machine`).
    The rules themselves are made per run: their strategies depend on the sensor's address
    and on the exploration's JUNK at the time of the run."""

    sensor: ClassVar[SensorSession]
    record: ClassVar[Exploration]
    marking: ClassVar[float | None]  # the marking foreign commands go out with

    def __init__(self) -> None:
        super().__init__()
        self.address = self.sensor.address
        self.trail: list[str] = []
        self.last_d0: str | None = None  # D0 reply since the last measurement command
        self.unheard = ""  # a foreign measurement command since then, silent but maybe taken
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
        if code[:1] in MEASURING:
            self.last_d0 = None  # a new measurement may change the data
            self.unheard = ""
        if not ex.answered:
            return
        if code in ("C", "CC"):
            self._wait_out(ex)
        stalled = _stalled(ex)  # read once for the framing, CRC and repeat observations
        self._observe_framing(ex, stalled)
        if code.startswith("D"):
            self._observe(Observation("crc", ex.text, ex.reply_text, stalled=stalled))
        if code == "D0":
            previous, unheard, late = self.last_d0, self.unheard, answered_late(ex)
            self._observe(
                Observation(
                    "repeat",
                    ex.text,
                    ex.reply_text,
                    previous=previous,
                    unheard=unheard,
                    late=late,
                    stalled=stalled,
                )
            )
            if not late:  # a reply that may be an earlier command's is no D0 to compare with
                # a reply the host stalled over may be cut: no D0 to hold the next one to
                self.last_d0 = None if stalled else ex.reply_text
                self.unheard = ""

    def _foreign(self, other: str, code: str) -> None:
        """A command to another address, sent the way the sensor was shown to hear."""
        ex = self.sensor.master.raw(f"{other}{code}!", break_first=True, marking=self.marking)
        self.record.exchanges.append(ex)
        self._note(f"{escape(ex.text)} (foreign) -> '{escape(ex.reply_text)}'")
        marked = self.marking is not None
        if code[:1] in MEASURING and not ex.answered and self._late():
            self.unheard = ex.text  # a reply would have come late: silence shows nothing
        self._observe(
            Observation(
                "foreign",
                ex.text,
                ex.reply_text,
                other,
                answered=ex.answered,
                marked=marked,
                collided=ex.maybe_collided,
                stalled=_stalled(ex),
            )
        )

    def _late(self) -> bool:
        """Whether the sensor has been seen to start its replies late: silence in the reply
        window then shows no command went unheard."""
        return self.sensor.master.watch.late.start is not None

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
            self.last_d0, self.unheard = None, ""

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

    def _observe_framing(self, ex: Exchange, stalled: str | None = None) -> None:
        """The framing of ``ex``'s reply; ``stalled``: :func:`_stalled` of it, where the
        caller read it already."""
        why = _stalled(ex) if stalled is None else stalled
        self._observe(Observation("framing", ex.text, ex.reply_text, self.address, stalled=why))

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


def foreign_addresses(sensor: SensorSession) -> list[str]:
    """The addresses the foreign commands go to (a strategy of the rules: part of a plan's
    key, ``exploration_machine.plan_for``)."""
    foreign = [a for a in "9zy" if a != sensor.address]
    if sensor.shared:  # never an address another sensor of the line answers at
        spare = "9zyxwv" + ADDRESS_CHARS[::-1]
        foreign = [
            a for a in dict.fromkeys(spare) if a != sensor.address and a not in sensor.others
        ]
        foreign = foreign[:3]
    return foreign


def plain_machine(
    sensor: SensorSession, record: Exploration, marking: float | None
) -> type[ExplorerSteps]:
    """The class that sends a stored plan for one run (:func:`release` it after the run)."""
    return type(
        "PlainExplorer",
        (ExplorerSteps,),
        {"sensor": sensor, "record": record, "marking": marking},
    )


def release_attributes(machine: type) -> None:
    """Drop the run a machine class was made for (its session, record and marking): a class
    is kept alive by its own reference cycles, and a process that never collects would keep
    the run's link, transcript and views with it."""
    for name in ("sensor", "record", "marking"):
        if name in vars(machine):
            delattr(machine, name)


def failure_exceptions() -> tuple[type[BaseException], ...]:
    """The exceptions that fail an example, as ``hypothesis.core.failure_exceptions_to_catch``
    gives them (``tests/sensor/test_exploration_plans.py`` compares the two)."""
    exceptions: list[type[BaseException]] = [Exception, SystemExit, GeneratorExit]
    if "_pytest.outcomes" in sys.modules:
        exceptions.append(sys.modules["_pytest.outcomes"].Failed)
    return tuple(exceptions)


def skip_exceptions() -> tuple[type[BaseException], ...]:
    """The exceptions that skip, as ``hypothesis.core.skip_exceptions_to_reraise`` gives
    them (the same test compares the two)."""
    exceptions = set()
    if "unittest" in sys.modules:
        exceptions.add(sys.modules["unittest"].SkipTest)
    if "_pytest.outcomes" in sys.modules:
        exceptions.add(sys.modules["_pytest.outcomes"].Skipped)
    return tuple(sorted(exceptions, key=str))


#: a function giving a tuple of exception classes, asked once per example as hypothesis does
Exceptions = Callable[[], tuple[type[BaseException], ...]]


def run_plan(
    machine: Callable[[], ExplorerSteps],
    plan: Plan,
    failures: Exceptions = failure_exceptions,
    skips: Exceptions = skip_exceptions,
) -> None:
    """Send ``plan`` with ``machine`` as hypothesis sends it (``exploration_machine.
    run_machine``): each example a new machine, its steps, its teardown (also after a step
    raised). The first example whose machine or step raises a failure ends the run, and, as
    hypothesis replays a failing example once to report it, it runs again from a new machine
    up to the step that raised (the replay's choices end there), and that step's exception,
    or the first one where the replay raised none, goes out."""
    for example in plan:
        failed = _run_example(machine, example, failures, skips)
        if failed is not None:
            index, first = failed
            again = _run_example(machine, example[: index + 1], failures, skips)
            try:
                raise (again[1] if again is not None else first)
            finally:  # the exception's traceback holds this frame: not the frame it
                del failed, first, again  # (a cycle, and through it the run: issue 22)


def _run_example(
    machine: Callable[[], ExplorerSteps],
    steps: tuple[Step, ...],
    failures: Exceptions,
    skips: Exceptions,
) -> tuple[int, BaseException] | None:
    """One example of :func:`run_plan`: None, or the index of the step that raised a failure
    (-1: the machine's making) and the exception. Hypothesis's own classes of exceptions:
    a skip and anything not a failure (Ctrl-C) go straight out, after the teardown."""
    failing, skipping = failures(), skips()
    try:
        made = machine()
    except skipping:
        raise
    except failing as exc:
        return -1, exc
    index = 0  # the step being sent
    try:
        for name, arguments in steps:
            made.step(name, arguments)
            index += 1
    except skipping:
        raise
    except failing as exc:
        return index, exc
    finally:
        made.teardown()
    return None


def _stalled(ex: Exchange) -> str:
    """Why what ``ex``'s reply shows may be the host's: its read was held up by a stall of the
    tool's own host (:attr:`~conformance.tool_recorder.records.Exchange.stall`); else ''."""
    return ex.stall.why() if ex.stall is not None else ""
