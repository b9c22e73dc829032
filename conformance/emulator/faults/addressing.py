"""Faults in addressing: foreign and old addresses, address changes, the factory address
and the wildcard (4.3, 4.4.3, 4.4.4).
"""

from __future__ import annotations

from dataclasses import replace

from ..profile import Profile
from ..replies import ReplyKind
from .edits import (
    only,
)
from .model import Fault


def _fresh_address_one(profile: Profile) -> Profile:
    return replace(profile, address="1")


def _address_quiet_2s(profile: Profile) -> Profile:
    return replace(profile, address_change_quiet=2.0)


#: Addressing.
ADDRESSING: tuple[Fault, ...] = (
    Fault(
        "answers-foreign-address",
        "a! and aI! are answered for every address (with that address), then standby; so"
        " its answer at a new address does not show it moved there (R-4.4.4-01, -02: seed"
        " 4104 beside address-change-not-applied).",
        ("R-4.0-01", "R-4.4.4-03"),
        settings={"answer_foreign": True},
        inconclusive=("R-4.4.4-01", "R-4.4.4-02"),
    ),
    Fault(
        "ignores-query",
        "?! gets no answer.",
        ("R-4.4.3-01", "R-4.4-01"),
        settings={"answer_query": False},
    ),
    Fault(
        "address-change-not-applied",
        "aAb! answers b but the sensor keeps its old address.",
        ("R-4.4.4-01", "R-4.4.4-03", "R-4.3-03"),
        settings={"apply_address_change": False},
    ),
    Fault(
        "answers-old-address",
        "After aAb! the sensor answers at b and still at its old address.",
        ("R-4.4.4-03", "R-4.0-01"),
        settings={"answer_old_address": True},
    ),
    Fault(
        "address-change-wrong-reply",
        "aAb! changes the address but answers with the old one.",
        ("R-4.4.4-01", "R-4.3-03"),
        rewrite=only(
            [ReplyKind.CHANGE_ADDRESS],
            lambda r: replace(r, body=r.command.address if r.command else r.body),
        ),
    ),
)


#: Added to complete the sensor-role coverage.
COVERAGE: tuple[Fault, ...] = (
    Fault(
        "factory-address-not-zero",
        "The sensor ships at address 1 instead of 0 (the simulated unit is fresh).",
        ("R-4.3-02",),
        profile=_fresh_address_one,
    ),
    Fault(
        "accepts-invalid-address",
        "aA$! makes '$' the sensor's address (only 0-9, A-Z, a-z are addresses).",
        ("R-4.3-04",),
        settings={"accept_any_new_address": True},
    ),
    Fault(
        "wildcard-wrong-reply",
        "?I! and other wildcard commands are answered with a bare address.",
        ("R-4.4.3-02",),
        settings={"wildcard_answer": True},
    ),
    Fault(
        "answers-trailing-address",
        "A command for another address whose character before '!' is this sensor's address"
        " (zD0! at '0') is answered as a! (a parser fed one character at a time that starts"
        " over at its address: the lagopus sketch on EnviroDIY's library, sixteenth round).",
        ("R-4.0-01",),
        settings={"answer_trailing_address": True},
    ),
    Fault(
        "address-change-deaf-2s",
        "After aAb! the sensor ignores every command for 2 s (1 s is allowed).",
        ("R-4.4.4-02",),
        profile=_address_quiet_2s,
    ),
)
