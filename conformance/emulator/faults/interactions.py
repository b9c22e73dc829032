"""Declared interactions between emulator faults, as data (issue 18, part 7).

A combination of faults is expected to be caught by the union of its members' ``violates``;
an :class:`Interaction` records where the combination genuinely changes what a correct tool
must say (one member hides another's deviation, or the two together break a further rule).
Each entry names its members, what it adds or removes, and why in one sentence. An entry is
never added to make a combination row pass: only where a correct tool's verdicts differ.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Interaction:
    """What a set of faults does together that the members alone do not explain."""

    members: frozenset[str]
    reason: str
    #: requirements the combination may FAIL/WARN beyond the members' ``violates``
    adds: tuple[str, ...] = ()
    #: members' requirements a correct tool may PASS or leave undecided in the combination
    #: (the deviation is masked; a PASS there is no missed FAIL)
    removes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if len(self.members) < 2:
            raise ValueError("an interaction needs two or more member faults")
        if not self.reason.strip():
            raise ValueError(f"interaction {sorted(self.members)} gives no reason")
        if not (self.adds or self.removes):
            raise ValueError(f"interaction {sorted(self.members)} changes nothing")

    def applies(self, combination: tuple[str, ...]) -> bool:
        return self.members <= set(combination)


#: No interaction is declared yet: the first measurement (notes/combos-result.md) found the
#: unexplained rows to be tool defects being fixed, not combinations that change the truth.
INTERACTIONS: tuple[Interaction, ...] = ()
