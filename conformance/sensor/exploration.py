"""Property-based exploration of a sensor: random sequences of valid commands, foreign
addresses, malformed commands, breaks and pauses, with invariants checked after every step.

A hypothesis state machine drives the master engine. It is derandomised, so every run sends
the same sequences (a certificate must be reproducible), and it never shrinks: a sensor keeps
state between examples (its data buffer, its address), so replaying a shorter sequence is not
the same experiment, and on real hardware a shrinking storm costs minutes of bus time. Each
invariant names the requirement it protects; the first broken one ends the exploration and
its step log becomes the evidence.
"""

from __future__ import annotations

import getpass
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

from hypothesis import HealthCheck, Phase, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, rule, run_state_machine_as_test

from ..protocol.commands import ADDRESS_CHARS, CommandError, Kind, parse_command
from ..protocol.crc import is_crc_char
from ..protocol.responses import parse_data_reply, split_line
from ..tool_recorder.records import Exchange
from ..transcript import escape
from .address_change import AddressChanger
from .session import SensorSession

#: Commands the exploration sends to the sensor's own address. Any next command aborts a
#: running measurement and pauses stay under 0.25 s, so no service request arrives unasked
#: inside another exchange.
OWN = ("", "I", "M", "MC", "C", "CC", "D0", "R0", "RC0")
FOREIGN_FORMS = ("", "I", "M", "D0", "C")


def _harmless(junk: str) -> bool:
    """Junk may spell a real command; never one that changes the device: a change of address
    (``aAb!``) or an extended command (``aX...!``, opt-in only: it may reconfigure a unit).
    Junk that starts with ``A`` is a change of address to a sensor that reads leniently
    (``0A.!`` taken as a move to '.'): the address cases judge those, with a restore."""
    if junk.startswith("A"):
        return False
    try:
        kind = parse_command(f"0{junk}!").kind
    except CommandError:
        return not junk.startswith("X")
    return kind not in (Kind.CHANGE_ADDRESS, Kind.EXTENDED)


JUNK = st.text(alphabet=st.sampled_from("MDCRIVXAB0123456789+-._#"), min_size=1, max_size=6).filter(
    _harmless
)
MAX_WAIT_OUT = 3  # s: the longest concurrent measurement the exploration waits out
IDS = ("R-4.0-01", "R-4.3-01", "R-4.2-03", "R-4.4.12-05", "R-4.4.12-06", "R-4.4.5-10")


class InvariantBroken(AssertionError):
    def __init__(self, requirement: str, message: str) -> None:
        super().__init__(f"{requirement}: {message}")
        self.requirement = requirement
        self.message = message


@dataclass
class Exploration:
    """What the exploration did: steps, exchanges, and the invariant that broke (if any)."""

    steps: int = 0
    log: list[str] = field(default_factory=list)
    exchanges: list[Exchange] = field(default_factory=list)
    broken: InvariantBroken | None = None
    failing_sequence: list[str] = field(default_factory=list)
    checked: dict[str, int] = field(default_factory=lambda: {rid: 0 for rid in IDS})


def explore(sensor: SensorSession, *, examples: int = 10, steps: int = 25) -> Exploration:
    record = Exploration()
    address = sensor.address
    foreign = [a for a in "9zy" if a != address]
    # foreign commands go out the way the sensor was shown to hear a one-shot a! (found
    # before the machine starts, so finding it disturbs no sequence); a sensor shown to hear
    # none leaves their silence uncounted
    marking = sensor.hearing_marking()

    class SensorMachine(RuleBasedStateMachine):
        def __init__(self) -> None:
            super().__init__()
            self.trail: list[str] = []
            self.last_d0: str | None = None  # D0 reply since the last measurement command
            sensor.master.send_break()

        def _broken(self, requirement: str, message: str) -> InvariantBroken:
            """The invariant that broke, kept as soon as it is seen: hypothesis replays a
            failing example to confirm it, and a real device, whose state moved on, may then
            behave otherwise (hypothesis calls that flaky); the first observation stands."""
            exc = InvariantBroken(requirement, message)
            if record.broken is None:
                record.broken = exc
                record.failing_sequence = list(self.trail)
            return exc

        def _wait_out(self, ex: Exchange) -> None:
            """A concurrent measurement runs on after its reply: wait its announced time, so
            anything it sends then (a faulty service request) lands in a pause of its own and
            is judged by the concurrent cases, not taken for the reply to the next step."""
            body, _ = split_line(ex.reply_text)
            ttt = body[1:4]
            if ttt.isdigit() and int(ttt) > 0:
                heard = sensor.listen(min(int(ttt), MAX_WAIT_OUT) + 0.05)
                self._note(f"wait {ttt} s" + (" (heard something)" if heard else ""))

        def _note(self, text: str) -> None:
            self.trail.append(text)
            record.steps += 1

        def _send(self, code: str) -> Exchange:
            ex = sensor.master.transact(f"{address}{code}!")
            record.exchanges.append(ex)
            self._note(f"{escape(ex.text)} -> '{escape(ex.reply_text)}'")
            return ex

        @rule(code=st.sampled_from(OWN))
        def own_command(self, code: str) -> None:
            ex = self._send(code)
            if code[:1] in ("M", "C", "V", "H"):
                self.last_d0 = None  # a new measurement may change the data
            if not ex.answered:
                return
            if code in ("C", "CC"):
                self._wait_out(ex)
            self._check_framing(ex)
            if code.startswith("D"):
                self._check_crc(ex)
            if code == "D0":
                self._check_repeat(ex)

        @rule(index=st.sampled_from(("0", "0", "1")))
        def read_data(self, index: str) -> None:
            """D replies, the place where the CRC and buffer invariants bite."""
            self.own_command(f"D{index}")

        @rule(other=st.sampled_from(foreign), code=st.sampled_from(FOREIGN_FORMS))
        def foreign_command(self, other: str, code: str) -> None:
            ex = sensor.master.raw(f"{other}{code}!", break_first=True, marking=marking)
            record.exchanges.append(ex)
            self._note(f"{escape(ex.text)} (foreign) -> '{escape(ex.reply_text)}'")
            if marking is not None or ex.answered:
                record.checked["R-4.0-01"] += 1
            if ex.answered:
                raise self._broken(
                    "R-4.0-01",
                    f"answered {escape(ex.text)}, a command for "
                    f"address '{other}', with '{escape(ex.reply_text)}'",
                )

        @rule(junk=JUNK)
        def malformed_command(self, junk: str) -> None:
            ex = sensor.master.raw(f"{address}{junk}!", break_first=None)
            record.exchanges.append(ex)
            self._note(f"{escape(ex.text)} (malformed?) -> '{escape(ex.reply_text)}'")
            if ex.answered:  # decision A12: silence or any well-framed reply is fine
                moved = moved_by_malformed(junk, ex.reply_text, address)
                if moved is not None:
                    self._follow_address_change(moved)
                    return
                self._check_framing(ex)
                # junk can spell a real command ("M", or "-7!0MC" ending in one): whatever
                # the sensor accepted may have started a measurement
                self.last_d0 = None

        @rule()
        def brk(self) -> None:
            sensor.master.send_break()
            self._note("break")

        @rule(seconds=st.sampled_from((0.01, 0.05, 0.12, 0.25)))
        def pause(self, seconds: float) -> None:
            sensor.listen(seconds)
            self._note(f"pause {seconds * 1e3:.0f} ms")

        def _follow_address_change(self, moved: str) -> None:
            """The sensor read the malformed command as ``aAb!`` and now answers at
            ``moved``: informative under decision A12, not a reply from the wrong address;
            put it back, so every later step talks to the address it has."""
            changer = AddressChanger(sensor.master, address)
            changer.current = moved
            changer.tried.append(moved)
            note = changer.restore()
            record.exchanges += changer.exchanges
            sensor.address_notes.append(note)
            self._note(f"taken as a change to address '{moved}' (decision A12); {note}")

        def _check_framing(self, ex: Exchange) -> None:
            body, framing = split_line(ex.reply_text)
            record.checked["R-4.2-03"] += 1
            record.checked["R-4.3-01"] += 1
            if [v for v in framing if v.requirement == "R-4.2-03"]:
                raise self._broken(
                    "R-4.2-03",
                    f"reply to {escape(ex.text)} '{escape(ex.reply_text)}' does not end in CR LF",
                )
            if body[:1] != address:
                raise self._broken(
                    "R-4.3-01",
                    f"reply to {escape(ex.text)} starts with '{escape(body[:1])}', not '{address}'",
                )

        def _check_crc(self, ex: Exchange) -> None:
            body, _ = split_line(ex.reply_text)
            if len(body) < 4 or not all(is_crc_char(c) for c in body[-3:]):
                return  # no CRC claimed: presence is judged by the D-reply cases
            reply = parse_data_reply(body, crc_expected=True, limit=75)
            for rid in ("R-4.4.12-05", "R-4.4.12-06"):
                record.checked[rid] += 1
                bad = [v for v in reply.violations if v.requirement == rid]
                if bad:
                    raise self._broken(rid, f"reply to {escape(ex.text)}: {bad[0].message}")

        def _check_repeat(self, ex: Exchange) -> None:
            record.checked["R-4.4.5-10"] += 1
            if self.last_d0 is not None and ex.reply_text != self.last_d0:
                raise self._broken(
                    "R-4.4.5-10",
                    f"D0 gave '{escape(self.last_d0)}', then "
                    f"'{escape(ex.reply_text)}' with no measurement between",
                )
            self.last_d0 = ex.reply_text

        def teardown(self) -> None:
            record.log.append(" ; ".join(self.trail))
            if record.broken is None:  # after a break, the sequence that broke it stays
                record.failing_sequence = list(self.trail)

    keep_hypothesis_out_of_the_working_folder()
    try:
        with no_local_constants():
            _run(SensorMachine, examples, steps)
    except BaseException as exc:  # hypothesis may wrap the failure; find ours inside
        broken = record.broken or _first_broken(exc)
        if broken is None or isinstance(exc, KeyboardInterrupt):
            raise
        record.broken = broken
    return record


def _run(machine: type[RuleBasedStateMachine], examples: int, steps: int) -> None:
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


@contextmanager
def no_local_constants() -> Iterator[None]:
    """Hypothesis draws now and then from the constants of the non-library modules loaded
    in the process (its "local constants"), so a derandomised exploration sent other
    sequences in a pytest process that had loaded other test modules than the CLI does: the
    same sensor got other stimuli, and other whole-run counts. A certificate's stimuli must
    not depend on what else the process imported: the exploration sees none of them (an
    internal of hypothesis; without it, the library's own behaviour stays)."""
    try:
        from hypothesis.internal.conjecture import providers

        original = providers._get_local_constants
        empty = providers.Constants()
        cache = providers.CONSTANTS_CACHE.cache
    except (ImportError, AttributeError):  # another hypothesis: nothing to hold still
        yield
        return
    cache.clear()  # it holds the local constants allowed per kind of draw
    providers._get_local_constants = lambda: empty
    try:
        yield
    finally:
        providers._get_local_constants = original
        cache.clear()


def moved_by_malformed(junk: str, reply: str, address: str) -> str | None:
    """The new address a sensor reports when it took the malformed ``a<junk>!`` as an
    address change (``0A1M!`` read as ``0A1!``, answered ``1``), else None."""
    body, _ = split_line(reply)
    if junk[:1] == "A" and len(body) == 1 and body != address and body in ADDRESS_CHARS:
        return body if junk[1:2] == body else None
    return None


def _first_broken(exc: BaseException | None) -> InvariantBroken | None:
    """The :class:`InvariantBroken` inside ``exc`` (itself, a group member, or a cause)."""
    seen: set[int] = set()
    stack = [exc]
    while stack:
        item = stack.pop(0)
        if item is None or id(item) in seen:
            continue
        seen.add(id(item))
        if isinstance(item, InvariantBroken):
            return item
        stack.extend(getattr(item, "exceptions", ()))
        stack.extend((item.__cause__, item.__context__))
    return None


def keep_hypothesis_out_of_the_working_folder() -> None:
    """Hypothesis caches (constants, unicode data) in ``./.hypothesis`` even with no example
    database; a conformance run must leave nothing in the user's folder but its reports.
    The cache goes to the user's cache folder unless HYPOTHESIS_STORAGE_DIRECTORY says where."""
    if os.environ.get("HYPOTHESIS_STORAGE_DIRECTORY"):
        return
    from hypothesis.configuration import set_hypothesis_home_dir

    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    home = os.path.join(base, "sdi12-conform", "hypothesis")
    try:
        os.makedirs(home, exist_ok=True)
    except OSError:  # no writable home: a per-user folder under the system's temp folder
        home = os.path.join(tempfile.gettempdir(), f"sdi12-conform-hypothesis-{getpass.getuser()}")
    set_hypothesis_home_dir(home)
