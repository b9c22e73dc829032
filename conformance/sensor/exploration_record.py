"""What an exploration of a sensor keeps and the fixed choices behind its stimuli: the record
of a run (:class:`Exploration`), the commands it may send, its seed, and the reading of a
malformed command as a change of address. No hypothesis here: :mod:`.exploration` and the
cases load this with every run, the state machine (:mod:`.exploration_machine`) only when an
exploration runs."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..judges.exploration import Breach, Observation, checks, first_breach
from ..protocol.commands import ADDRESS_CHARS, CommandError, Kind, parse_command
from ..protocol.responses import split_line
from ..tool_recorder.records import Exchange

#: Commands the exploration sends to the sensor's own address. Any next command aborts a
#: running measurement and pauses stay under 0.25 s, so no service request arrives unasked
#: inside another exchange.
OWN = ("", "I", "M", "MC", "C", "CC", "D0", "R0", "RC0")
FOREIGN_FORMS = ("", "I", "M", "D0", "C")


def harmless(junk: str) -> bool:
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


MAX_WAIT_OUT = 3  # s: the longest concurrent measurement the exploration waits out


#: The seed of the exploration's draws. Derandomised, hypothesis would derive it from the
#: source of the state machine class, so any edit of the machine's code (a refactor, a
#: docstring) changed the stimuli a certificate sends; pinned, the stimuli change only when
#: what is drawn changes. The value is the one hypothesis 6.155 derived from the machine
#: before the judging moved to :mod:`conformance.judges.exploration`, so that refactor sent
#: the same sequences.
SEED = int(
    "329558160193879476134443644708594822412186838105239847808910"
    "47179689026151828737661106160451612292821512896840224222"
)


class InvariantBroken(AssertionError):
    """Raised inside a rule to end the example at the first breach the judges find."""

    def __init__(self, requirement: str, message: str) -> None:
        super().__init__(f"{requirement}: {message}")
        self.requirement = requirement
        self.message = message


@dataclass
class Exploration:
    """What the exploration did: steps, exchanges, and the observations the judges decide
    (the invariant that broke, if any, and how often each was checked)."""

    steps: int = 0
    log: list[str] = field(default_factory=list)
    exchanges: list[Exchange] = field(default_factory=list)
    observations: list[Observation] = field(default_factory=list)
    failing_sequence: list[str] = field(default_factory=list)
    #: whether an observation so far broke an invariant (``broken`` judges them all again;
    #: asked at every step, that was quadratic in the exploration's length)
    breached: bool = False

    @property
    def broken(self) -> Breach | None:
        """The first invariant broken, as the judges see the observations."""
        return first_breach(self.observations)

    @property
    def checked(self) -> dict[str, int]:
        """How many checks each requirement in :data:`IDS` got."""
        return checks(self.observations)


def moved_by_malformed(junk: str, reply: str, address: str) -> str | None:
    """The new address a sensor reports when it took the malformed ``a<junk>!`` as an
    address change (``0A1M!`` read as ``0A1!``, answered ``1``), else None."""
    body, _ = split_line(reply)
    if junk[:1] == "A" and len(body) == 1 and body != address and body in ADDRESS_CHARS:
        return body if junk[1:2] == body else None
    return None
