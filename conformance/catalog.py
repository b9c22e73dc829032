"""The SDI-12 requirements catalogue (``catalog.json``) as typed, immutable records.

Why a data file: every test case, finding and report refers to requirements by the stable IDs of
``spec/requirements.md`` section 1, and reports need the clause, level and applicability of each
ID. Keeping that in one JSON file (rather than scattered constants) means the plugin, the judges
and the report writers can never disagree about what a requirement says, which role it binds, or
whether a violation is a FAIL (MUST) or a WARN (SHOULD/MAY).

The file is loaded once, lazily, through :mod:`importlib.resources` so it works from an installed
wheel as well as from a source tree. Loading validates every field: a malformed catalog is a bug
in the tool and must stop it loudly rather than yield silently wrong verdicts.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from importlib.resources import files
from typing import Any

from .protocol.version import format_version

__all__ = [
    "CHECK_KINDS",
    "LEVELS",
    "ROLES",
    "SCHEMA",
    "VERSIONS",
    "Requirement",
    "catalog",
    "decisions",
    "for_role",
    "requirement",
    "strongest_verdict",
]

SCHEMA = "sdi12-conform/catalog/1"

#: Roles a requirement can bind. "both" means it binds sensors and recorders alike.
ROLES = ("sensor", "recorder", "both")
#: Normalised requirement levels; qualifiers such as "(impl.)" live in ``level_note``.
LEVELS = ("MUST", "MUST NOT", "SHOULD", "MAY")
#: How the tool can check a rule (legend of requirements.md section 0).
CHECK_KINDS = (
    "protocol",
    "protocol(raw)",
    "break",
    "timing",
    "electrical",
    "inspection",
    "recorder",
)
#: SDI-12 versions the catalog distinguishes (value of ``since``).
VERSIONS = ("1.3", "1.4")

# The tool's two roles: which check kinds it can carry out while playing each of them.
# Playing the recorder (judging a sensor) it can drive protocol exchanges, raw bytes, breaks and
# timing; playing sensors (judging a recorder) it observes the recorder, its timing and breaks.
_TESTABLE_KINDS = {
    "sensor": frozenset({"protocol", "protocol(raw)", "break", "timing"}),
    "recorder": frozenset({"recorder", "timing", "break"}),
}


def _check_role(role: str) -> str:
    """Validate a DUT role argument; "both" is a catalog value, not a role the tool can play."""
    if role not in _TESTABLE_KINDS:
        raise ValueError(f"role must be 'sensor' or 'recorder', not {role!r}")
    return role


def _normalise_version(version: str) -> str:
    """Map an ``aI!`` version field ("13") or a dotted version ("1.3") to "1.3"/"1.4".

    Anything else is refused: the catalog only covers v1.3 and v1.4, and guessing which rules
    bind a device claiming, say, "12" would produce verdicts the standard does not support.
    """
    text = version.strip()
    if len(text) == 2 and text.isdigit():
        text = format_version(text)
    if text not in VERSIONS:
        raise ValueError(
            f"SDI-12 version {version!r} is not covered by the catalog "
            f"(expected one of '13', '14', '1.3', '1.4')"
        )
    return text


@dataclass(frozen=True)
class Requirement:
    """One row of requirements.md section 1.

    ``check`` lists the check kinds of the Check column; ``note`` carries its qualifiers
    (e.g. the electrical part the tool cannot see) and other caveats. ``since`` is the lowest
    claimed SDI-12 version whose devices the rule binds.
    """

    id: str
    clause: str
    ver: str
    role: str
    level: str
    level_note: str | None
    statement: str
    check: tuple[str, ...]
    since: str
    sensor_testable: bool
    recorder_testable: bool
    untestable_reason: str | None
    decisions: tuple[str, ...]
    note: str | None

    def applies_to_role(self, role: str) -> bool:
        """True if the rule binds a DUT of ``role`` ("sensor"/"recorder"), itself or as "both"."""
        return self.role in (_check_role(role), "both")

    def testable(self, role: str) -> bool:
        """True if the tool can judge this rule when the DUT has ``role``."""
        if _check_role(role) == "sensor":
            return self.sensor_testable
        return self.recorder_testable

    def applies_to_version(self, version: str) -> bool:
        """True if a device claiming ``version`` ("13"/"14" or "1.3"/"1.4") is bound by the rule."""
        return VERSIONS.index(_normalise_version(version)) >= VERSIONS.index(self.since)

    @property
    def is_should(self) -> bool:
        """True for SHOULD/MAY rules, whose violation is a WARN rather than a FAIL."""
        return self.level in ("SHOULD", "MAY")


def _require(cond: bool, rid: str, message: str) -> None:
    """Raise a uniform error for a malformed catalog entry."""
    if not cond:
        raise ValueError(f"catalog.json: {rid}: {message}")


def _build(entry: dict[str, Any], decision_labels: frozenset[str]) -> Requirement:
    """Turn one JSON entry into a :class:`Requirement`, checking every enumerated field."""
    rid = entry.get("id", "<no id>")
    req = Requirement(
        id=entry["id"],
        clause=entry["clause"],
        ver=entry["ver"],
        role=entry["role"],
        level=entry["level"],
        level_note=entry["level_note"],
        statement=entry["statement"],
        check=tuple(entry["check"]),
        since=entry["since"],
        sensor_testable=entry["sensor_testable"],
        recorder_testable=entry["recorder_testable"],
        untestable_reason=entry["untestable_reason"],
        decisions=tuple(entry["decisions"]),
        note=entry["note"],
    )
    _require(req.role in ROLES, rid, f"bad role {req.role!r}")
    _require(req.level in LEVELS, rid, f"bad level {req.level!r}")
    _require(req.since in VERSIONS, rid, f"bad since {req.since!r}")
    _require(bool(req.check), rid, "empty check list")
    _require(all(k in CHECK_KINDS for k in req.check), rid, f"bad check kinds {req.check!r}")
    _require(
        isinstance(req.sensor_testable, bool) and isinstance(req.recorder_testable, bool),
        rid,
        "testability flags must be booleans",
    )
    unknown = set(req.decisions) - decision_labels
    _require(not unknown, rid, f"unknown decision labels {sorted(unknown)}")
    return req


@cache
def _load() -> tuple[dict[str, Requirement], dict[str, str]]:
    """Read and validate catalog.json once per process."""
    raw = json.loads(files("conformance").joinpath("catalog.json").read_text(encoding="utf-8"))
    if raw.get("schema") != SCHEMA:
        raise ValueError(f"catalog.json: schema is {raw.get('schema')!r}, expected {SCHEMA!r}")
    decision_map: dict[str, str] = dict(raw["decisions"])
    labels = frozenset(decision_map)
    reqs: dict[str, Requirement] = {}
    for entry in raw["requirements"]:
        req = _build(entry, labels)
        if req.id in reqs:
            raise ValueError(f"catalog.json: duplicate requirement {req.id}")
        reqs[req.id] = req
    return reqs, decision_map


def catalog() -> dict[str, Requirement]:
    """All requirements keyed by ID, in requirements.md order (a fresh dict; records are frozen)."""
    return dict(_load()[0])


def requirement(id: str) -> Requirement:  # the public API names the argument "id"
    """The requirement with this ID; a KeyError names the ID so typos in markers are obvious."""
    try:
        return _load()[0][id]
    except KeyError:
        raise KeyError(
            f"unknown requirement ID {id!r}: not in requirements.md section 1 "
            f"(IDs look like 'R-4.4.6-02')"
        ) from None


def for_role(role: str) -> list[Requirement]:
    """Requirements binding a DUT of ``role`` ("sensor"/"recorder"), in catalog order."""
    _check_role(role)
    return [r for r in _load()[0].values() if r.applies_to_role(role)]


def strongest_verdict(id: str) -> str:  # noqa: A002 - same argument name as requirement()
    """The harshest verdict a broken rule can get: "FAIL" for MUST/MUST NOT, "WARN" for
    SHOULD/MAY (a MAY never fails a device). IDs outside the catalog (unit-test fixtures)
    keep "FAIL"; the marker check refuses them in real cases."""
    req = _load()[0].get(id)
    return "WARN" if req is not None and req.is_should else "FAIL"


def decisions() -> dict[str, str]:
    """Decisions, label -> one-line summary: requirements.md section 5's ("A1".."A18"), then
    the tool's own ("T1".. : allowances and readings the standard does not give, each with
    its reason and figure, cited in the findings they shape)."""
    return dict(_load()[1])
