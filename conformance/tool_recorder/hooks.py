"""The declared points where a recorder built on the tool recorder may deviate from it.

The recorder role's fault-detection matrix needs faulty recorders (one that retries too
early, one that never breaks after 87 ms of marking, one that accepts a bad CRC...), and the
sensor session needs to watch what each attempt got back. Both used to subclass
:class:`~conformance.tool_recorder.engine.ToolRecorder` and override its private methods, so any
change inside the engine could silently change what a fault does. :class:`Hooks` names the
few decisions the engine lets others take instead: the engine calls a hook at each of those
points, hands it the engine's own behaviour (``usual`` or ``proceed``, a callable that does
what the engine would do), and uses what the hook returns. The defaults return exactly that,
so ``ToolRecorder(link)`` behaves as it always did. A stateful deviation keeps its state on its
own hooks object, one per engine.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from ..links.base import Link
    from ..protocol.commands import Command
    from .policy import Policy
    from .records import Attempt, Exchange, Measurement


class Engine(Protocol):
    """What a hook may use of the engine that calls it: its link, its policy and the address
    it last sent to. The engine is :class:`~conformance.tool_recorder.engine.ToolRecorder`; naming
    it here would make the two modules import each other."""

    link: Link
    policy: Policy
    last_address: str | None


class Hooks:
    """The engine's deviation points; every default does what the engine itself does."""

    def retry_time(
        self,
        master: Engine,
        exchange: Exchange,
        sequence: int,
        per_sequence: int,
        usual: Callable[[], float],
    ) -> float:
        """When the next retry (no break) of ``exchange`` starts; ``usual()`` is the engine's
        time per R-7.2-02/03/06. Called only before a retry, never before a sequence."""
        return usual()

    def needs_break(
        self, master: Engine, address: str, at: float, usual: Callable[[], bool]
    ) -> bool:
        """Whether a command to ``address`` transmitted at ``at`` gets a break in front, when
        the caller left it to the break rules; ``usual()`` is R-7.0-17 / R-7.1-01."""
        return usual()

    def wait_for_data(
        self,
        master: Engine,
        m: Measurement,
        service_request: bool,
        usual: Callable[[], None],
    ) -> None:
        """Wait for the data of measurement ``m`` (ttt > 0), recording what the DUT sends
        meanwhile; ``usual()`` waits out ttt, or up to the service request when
        ``service_request``. It reads ``m`` when called, so a hook may change ``m`` first."""
        usual()

    def attempt(
        self,
        master: Engine,
        wire: bytes,
        address: str,
        command: Command | None,
        proceed: Callable[[], Attempt],
    ) -> Attempt:
        """One transmission of ``wire`` (to ``address``; ``command`` None when it does not
        parse) and its reply; ``proceed()`` listens before talk, sends it and reads and judges
        the reply. A hook may wait before it, or change the attempt it returns."""
        return proceed()

    def command_gap(self, master: Engine, gap: float) -> float:
        """The marking left between the characters of a command the caller asked to send
        with ``gap`` between them (0: back to back, R-7.0-13)."""
        return gap
