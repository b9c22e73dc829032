"""Changing the DUT's address safely (design.md 7: leave the DUT as found).

Every change is paired with a restore in a ``finally``, so a failure, an exception or Ctrl-C
still puts the sensor back at its original address, and the note says whether that worked.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .master.engine import Master
from .master.records import Exchange
from .protocol.responses import split_line
from .protocol.timing import ADDRESS_CHANGE_QUIET

POLL_INTERVAL = 0.2  # s between "are you there at the new address?" polls
LATE_LIMIT = 3.0  # s: how long past the 1 s allowance the tool keeps polling for evidence


@dataclass
class ChangeOutcome:
    """One ``aAb!`` and what followed: when the sensor answered at the new address."""

    request: Exchange
    took: bool
    answered_after: float | None = None  # s from the aAb! reply to the first answer at b
    polls: list[Exchange] = field(default_factory=list)


class AddressChanger:
    def __init__(self, master: Master, original: str) -> None:
        self.master = master
        self.original = original
        self.current = original
        self.exchanges: list[Exchange] = []
        self.restored: bool | None = None

    def change(self, new: str, *, wait_for_answer: bool = True) -> ChangeOutcome:
        ex = self.master.change_address(new, address=self.current)
        self.exchanges.append(ex)
        body, _ = split_line(ex.reply_text)
        took = ex.answered and body == new
        outcome = ChangeOutcome(ex, took)
        if took:
            self.current = new
            if wait_for_answer:
                self._await_answer(outcome)
        return outcome

    def _await_answer(self, outcome: ChangeOutcome) -> None:
        """Poll ``b!`` until the sensor answers; a sensor may be deaf for 1 s (R-4.4.4-02)."""
        link = self.master.link
        start = outcome.request.end
        while link.now() - start < ADDRESS_CHANGE_QUIET + LATE_LIMIT:
            poll = self.master.transact(f"{self.current}!")  # with retries: a slow waker
            outcome.polls.append(poll)
            self.exchanges.append(poll)
            if poll.answered:
                outcome.answered_after = poll.last.command_events[0].start - start  # answered try
                return
            link.wait(POLL_INTERVAL)

    def restore(self) -> str:
        """Put the sensor back at its original address; returns a note for the report."""
        if self.current == self.original:
            self.restored = True
            return f"address restored to '{self.original}'"
        outcome = self.change(self.original)
        self.restored = outcome.took and outcome.answered_after is not None
        if not self.restored:  # the change back failed: maybe it never left the original
            check = self.master.transact(f"{self.original}!")
            self.exchanges.append(check)
            if check.answered:
                self.current = self.original
                self.restored = True
                return f"the sensor answers at its original address '{self.original}'"
        if self.restored:
            return f"address restored to '{self.original}'"
        return (
            f"COULD NOT restore the address: the sensor may be left at '{self.current}' "
            f"(it was '{self.original}')"
        )
