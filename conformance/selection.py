"""A partial run: the cases a user selected (``-k``, ``--req``) and what that leaves out.

A selection is deliberate, so the requirements only the left-out cases judge are *not
selected* (said so, and left out of the counts and the verdict), never INCONCLUSIVE, which
would blame the device for the user's choice. A requirement that a selected case should have
judged and did not stays INCONCLUSIVE.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from .catalog import Requirement, for_role

NOT_SELECTED = "not selected: this partial run left out every case that judges it"


class SelectionError(ValueError):
    """A ``--req`` that names no requirement of the role (a usage error)."""


def matches(req: Requirement, wanted: str) -> bool:
    """``R-4.4.6-02`` (an ID, any case) or ``4.4.12`` (a clause and its sub-clauses)."""
    text = wanted.strip()
    if text.upper().startswith("R-"):
        return req.id.upper() == text.upper()
    clause = text.removeprefix("§").rstrip(".")
    id_clause = req.id.split("-")[1]  # R-4.4.12-02 -> 4.4.12
    clauses = {id_clause, *(part.strip() for part in req.clause.split(","))}
    return any(c == clause or c.startswith(clause + ".") for c in clauses)


def resolve(role: str, wanted: Iterable[str]) -> set[str]:
    """The testable requirement IDs of ``role`` that ``--req`` values name."""
    chosen: set[str] = set()
    for text in wanted:
        found = {r.id for r in for_role(role) if matches(r, text)}
        if not found:
            raise SelectionError(
                f"--req {text}: no {role} requirement has this ID or clause "
                f"(`sdi12-conform list --role {role}` shows them)"
            )
        testable = {rid for rid in found if _testable(rid, role)}
        if not testable:
            raise SelectionError(
                f"--req {text}: not testable by this tool in the {role} role "
                f"(`sdi12-conform list --role {role}` says why)"
            )
        chosen |= testable
    return chosen


def _testable(rid: str, role: str) -> bool:
    return any(r.id == rid and r.testable(role) for r in for_role(role))


@dataclass
class Selection:
    """What the run's selection left in and out (empty: a full run)."""

    how: list[str] = field(default_factory=list)  # "-k crc", "--req 4.4.12"
    left_out: set[str] = field(default_factory=set)  # requirements of deselected cases
    kept: set[str] = field(default_factory=set)  # requirements of selected cases

    @property
    def partial(self) -> bool:
        return bool(self.left_out)

    def not_selected(self) -> frozenset[str]:
        """Requirements only left-out cases judge."""
        return frozenset(self.left_out - self.kept)

    def describe(self) -> str:
        return " ".join(self.how) or "a subset of the cases"
