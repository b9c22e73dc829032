"""Tests for the requirements catalog (conformance/catalog.json + conformance/catalog.py).

The catalog is the contract every finding and report relies on, so these tests hold it against
its source, requirements.md section 1, parsed afresh at test time: same IDs in the same order,
same clause/version/role/level/check data, statements that paraphrase rather than copy, decision
labels that exist, and testability flags that follow the documented rule.
"""

from __future__ import annotations

import dataclasses
import difflib
import json
import re
from importlib.resources import files
from typing import Any

import pytest

from conformance import catalog as cat
from tests.support.paths import SHARED

SPEC = SHARED / "spec" / "requirements.md"

# Above this similarity (difflib ratio of normalised text) a "paraphrase" is a near-copy.
MAX_SIMILARITY = 0.80
MAX_STATEMENT_CHARS = 160
DECISION_LABELS = [f"A{i}" for i in range(1, 19)]
#: The tool's own decisions (issue 20): tolerances and readings the standard does not give,
#: after section 5's, each with its reason; a requirement they shape carries their label.
TOOL_DECISIONS = ["T1", "T2"]


# --------------------------------------------------------------------------- spec parsing


def _spec_text() -> str:
    if not SPEC.is_file():
        pytest.skip(f"requirements.md not found at {SPEC}; cannot compare the catalog with it")
    return SPEC.read_text(encoding="utf-8")


def _section(text: str, number: str) -> str:
    """The body of top-level section ``## <number>.`` of requirements.md."""
    match = re.search(rf"^## {re.escape(number)}\.(.*?)(?=^## |\Z)", text, re.M | re.S)
    assert match, f"section {number} not found in requirements.md"
    return match.group(1)


@pytest.fixture(scope="module")
def spec_rows() -> list[dict[str, str]]:
    """Every requirement row of requirements.md section 1, in document order."""
    rows = []
    for line in _section(_spec_text(), "1").splitlines():
        if not line.startswith("| R-"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        assert len(cells) == 7, f"unexpected table row: {line}"
        keys = ("id", "clause", "ver", "role", "level", "statement", "check")
        rows.append(dict(zip(keys, cells, strict=True)))
    return rows


@pytest.fixture(scope="module")
def raw() -> dict[str, Any]:
    """catalog.json as plain data, bypassing the loader's own de-duplication."""
    text = files("conformance").joinpath("catalog.json").read_text(encoding="utf-8")
    return json.loads(text)


def _spec_check_kinds(text: str) -> list[str]:
    """Check kinds named outside parentheses in a Check cell ("(+ electrical)" is a qualifier)."""
    bare = re.sub(r"\([^)]*\)", " ", text.replace("protocol(raw)", "PROTOCOL_RAW"))
    kinds: list[str] = []
    for word in re.findall(
        r"PROTOCOL_RAW|protocol|break|timing|electrical|inspection|recorder", bare
    ):
        kind = "protocol(raw)" if word == "PROTOCOL_RAW" else word
        if kind not in kinds:
            kinds.append(kind)
    return kinds


def _normalise(text: str) -> str:
    """Lower-case words and numbers only, so markup and punctuation do not hide a copy."""
    return " ".join(re.sub(r"[^0-9a-z]+", " ", text.lower()).split())


# --------------------------------------------------------------------------- against the spec


def test_ids_match_requirements_md_in_order(spec_rows: list[dict[str, str]]) -> None:
    spec_ids = [row["id"] for row in spec_rows]
    assert len(spec_ids) == 148
    assert list(cat.catalog()) == spec_ids


def test_table_columns_carried_over(spec_rows: list[dict[str, str]]) -> None:
    reqs = cat.catalog()
    for row in spec_rows:
        req = reqs[row["id"]]
        assert req.clause == row["clause"], req.id
        assert req.ver == row["ver"], req.id
        assert req.role == ("sensor" if row["role"] == "sensor / tool" else row["role"]), req.id
        assert req.check == tuple(_spec_check_kinds(row["check"])), req.id
        # "1.0-1.3" and "1.3†YYYY" rules bind v1.3 claims; "1.4"/"1.4‡2023" only v1.4 ones.
        assert req.since == ("1.4" if row["ver"].startswith("1.4") else "1.3"), req.id


def test_levels_normalised_with_original_kept(spec_rows: list[dict[str, str]]) -> None:
    reqs = cat.catalog()
    for row in spec_rows:
        req = reqs[row["id"]]
        original = row["level"]
        if original in cat.LEVELS:
            assert (req.level, req.level_note) == (original, None), req.id
        else:
            assert req.level_note == original, req.id
            if original.startswith("MUST (2000) / SHOULD"):
                assert req.level == "SHOULD", req.id  # the rule as revised in 2013
            else:
                assert original.startswith(req.level + " "), req.id
                assert not original.startswith("MUST NOT") or req.level == "MUST NOT", req.id


def test_statements_paraphrase_not_copy(spec_rows: list[dict[str, str]]) -> None:
    reqs = cat.catalog()
    for row in spec_rows:
        mine = _normalise(reqs[row["id"]].statement)
        theirs = _normalise(row["statement"])
        assert mine != theirs, f"{row['id']}: statement is a verbatim copy"
        ratio = difflib.SequenceMatcher(None, mine, theirs).ratio()
        assert ratio < MAX_SIMILARITY, f"{row['id']}: statement too close to spec ({ratio:.2f})"


def test_decisions_cover_section_5(spec_rows: list[dict[str, str]]) -> None:
    text = _section(_spec_text(), "5")
    blocks = re.split(r"^\* \*\*(A\d+)\.", text, flags=re.M)
    named = {blocks[i]: blocks[i + 1] for i in range(1, len(blocks) - 1, 2)}
    assert list(named) == DECISION_LABELS
    assert list(cat.decisions()) == DECISION_LABELS + TOOL_DECISIONS
    reqs = cat.catalog()
    # A requirement ID written into a decision's text must carry that decision's label.
    for label, body in named.items():
        for rid in re.findall(r"R-[\w.]+-\d\d", body):
            assert label in reqs[rid].decisions, f"{rid} should reference {label}"
    # ...and the spec rows that cite a decision ("see §5 A1") likewise.
    for row in spec_rows:
        for label in re.findall(r"§5 (A\d+)", row["statement"]):
            assert label in reqs[row["id"]].decisions, f"{row['id']} should reference {label}"


# --------------------------------------------------------------------------- self-consistency


def test_schema_and_top_level(raw: dict[str, Any]) -> None:
    assert raw["schema"] == cat.SCHEMA == "sdi12-conform/catalog/1"
    assert list(raw["decisions"]) == DECISION_LABELS + TOOL_DECISIONS
    for label, summary in raw["decisions"].items():
        assert summary and "\n" not in summary, label


def test_tool_decisions_state_their_figures_and_bind_what_they_name() -> None:
    """A tolerance of the tool's own is a stated decision: its figure in its text, and every
    requirement it names carries its label (so findings on it can cite it)."""
    reqs = cat.catalog()
    for label in TOOL_DECISIONS:
        text = cat.decisions()[label]
        assert re.search(r"\d+(\.\d+)? (ms|s)\b", text), label
        for rid in re.findall(r"R-[\w.]+-\d\d", text):
            assert label in reqs[rid].decisions, f"{rid} should reference {label}"


def test_no_duplicate_ids(raw: dict[str, Any]) -> None:
    ids = [entry["id"] for entry in raw["requirements"]]
    assert len(ids) == len(set(ids)) == 148


def test_entries_have_exactly_the_schema_fields(raw: dict[str, Any]) -> None:
    fields = {f.name for f in dataclasses.fields(cat.Requirement)}
    for entry in raw["requirements"]:
        assert set(entry) == fields, entry["id"]


def test_enumerated_fields_valid() -> None:
    for req in cat.catalog().values():
        assert re.fullmatch(r"R-(\d+(\.\d+)*|AppB)-\d\d", req.id), req.id
        assert req.role in cat.ROLES, req.id
        assert req.level in cat.LEVELS, req.id
        assert req.since in cat.VERSIONS, req.id
        assert req.check and set(req.check) <= set(cat.CHECK_KINDS), req.id
        assert len(set(req.check)) == len(req.check), req.id


def test_statements_are_single_short_lines() -> None:
    for req in cat.catalog().values():
        assert req.statement.strip() == req.statement and req.statement, req.id
        assert "\n" not in req.statement, req.id
        assert len(req.statement) <= MAX_STATEMENT_CHARS, req.id


def test_decision_labels_exist_and_all_are_used() -> None:
    labels = set(cat.decisions())
    used: set[str] = set()
    for req in cat.catalog().values():
        assert set(req.decisions) <= labels, req.id
        assert len(set(req.decisions)) == len(req.decisions), req.id
        used.update(req.decisions)
    assert used == labels, f"decisions bearing on no requirement: {sorted(labels - used)}"


def test_testability_follows_rule() -> None:
    sensor_kinds = {"protocol", "protocol(raw)", "break", "timing"}
    recorder_kinds = {"recorder", "timing", "break"}
    for req in cat.catalog().values():
        kinds = set(req.check)
        expect_sensor = req.role in ("sensor", "both") and bool(kinds & sensor_kinds)
        expect_recorder = req.role in ("recorder", "both") and bool(kinds & recorder_kinds)
        assert req.sensor_testable is expect_sensor, req.id
        assert req.recorder_testable is expect_recorder, req.id
        assert req.testable("sensor") is expect_sensor, req.id
        assert req.testable("recorder") is expect_recorder, req.id


def test_untestable_reason_iff_untestable_in_own_role() -> None:
    for req in cat.catalog().values():
        gaps = [
            role
            for role in ("sensor", "recorder")
            if req.applies_to_role(role) and not req.testable(role)
        ]
        if gaps:
            assert req.untestable_reason and req.untestable_reason.endswith("."), req.id
        else:
            assert req.untestable_reason is None, req.id


def test_electrical_and_inspection_only_rules_untestable() -> None:
    for req in cat.catalog().values():
        if set(req.check) <= {"electrical", "inspection"}:
            assert not req.sensor_testable and not req.recorder_testable, req.id


def test_counts_per_role() -> None:
    reqs = list(cat.catalog().values())
    sensor = [r for r in reqs if r.sensor_testable]
    recorder = [r for r in reqs if r.recorder_testable]
    neither = [r for r in reqs if not r.sensor_testable and not r.recorder_testable]
    print(
        f"\ncatalog: {len(reqs)} requirements; sensor role: {len(cat.for_role('sensor'))} apply, "
        f"{len(sensor)} testable; recorder role: {len(cat.for_role('recorder'))} apply, "
        f"{len(recorder)} testable; untestable in every role: {len(neither)}"
    )
    # Pinned so an edit that silently changes coverage shows up in review.
    assert (len(reqs), len(sensor), len(recorder), len(neither)) == (148, 106, 36, 12)
    assert len(cat.for_role("sensor")) == 115
    assert len(cat.for_role("recorder")) == 51


# --------------------------------------------------------------------------- API


def test_requirement_lookup_and_unknown_id() -> None:
    req = cat.requirement("R-4.4.6-02")
    assert req.id == "R-4.4.6-02" and req.role == "sensor" and req.check == ("protocol(raw)",)
    assert "A5" in req.decisions
    with pytest.raises(KeyError, match=r"R-9\.9-99"):
        cat.requirement("R-9.9-99")


def test_requirement_is_frozen() -> None:
    req = cat.requirement("R-4.4.1-01")
    with pytest.raises(dataclasses.FrozenInstanceError):
        req.level = "MAY"  # type: ignore[misc]


def test_catalog_returns_independent_copy() -> None:
    first = cat.catalog()
    first.pop("R-4.4.1-01")
    assert "R-4.4.1-01" in cat.catalog()


def test_applies_to_role() -> None:
    assert cat.requirement("R-4.0-01").applies_to_role("sensor")
    assert not cat.requirement("R-4.0-01").applies_to_role("recorder")
    both = cat.requirement("R-7.0-01")
    assert both.applies_to_role("sensor") and both.applies_to_role("recorder")
    with pytest.raises(ValueError, match="role"):
        both.applies_to_role("both")
    with pytest.raises(ValueError, match="role"):
        both.testable("logger")


def test_for_role_membership_and_order() -> None:
    order = list(cat.catalog())
    for role in ("sensor", "recorder"):
        selected = cat.for_role(role)
        assert all(r.role in (role, "both") for r in selected)
        positions = [order.index(r.id) for r in selected]
        assert positions == sorted(positions)
    sensor_ids = {r.id for r in cat.for_role("sensor")}
    assert "R-7.0-01" in sensor_ids and "R-7.2-01" not in sensor_ids
    with pytest.raises(ValueError):
        cat.for_role("both")


def test_applies_to_version() -> None:
    new_in_14 = cat.requirement("R-5.1-01")
    old = cat.requirement("R-4.4.1-01")
    clarified = cat.requirement("R-4.4.5-02")  # 1.3†2013: binds v1.3 claims too
    assert new_in_14.since == "1.4" and old.since == "1.3" and clarified.since == "1.3"
    for version in ("13", "1.3"):
        assert not new_in_14.applies_to_version(version)
        assert old.applies_to_version(version)
        assert clarified.applies_to_version(version)
    for version in ("14", "1.4", " 14 "):
        assert new_in_14.applies_to_version(version)
        assert old.applies_to_version(version)
    for bad in ("12", "15", "1.5", "", "x"):
        with pytest.raises(ValueError, match="not covered"):
            old.applies_to_version(bad)


def test_is_should() -> None:
    assert cat.requirement("R-4.4-03").is_should  # SHOULD
    assert cat.requirement("R-4.4.3-02").is_should  # MAY
    assert cat.requirement("R-4.4.7-07").is_should  # MUST (2000) / SHOULD (>=2013)
    assert not cat.requirement("R-4.0-01").is_should  # MUST NOT
    assert not cat.requirement("R-4.4.1-01").is_should  # MUST
    assert not cat.requirement("R-6.2-05").is_should  # MUST ("shall")


def test_loader_rejects_malformed_entry() -> None:
    entry = json.loads(files("conformance").joinpath("catalog.json").read_text(encoding="utf-8"))[
        "requirements"
    ][0]
    labels = frozenset(DECISION_LABELS)
    assert cat._build(entry, labels).id == entry["id"]
    for field, value in (
        ("role", "logger"),
        ("level", "MUSTN'T"),
        ("since", "1.2"),
        ("check", ["oscilloscope"]),
        ("check", []),
        ("decisions", ["A99"]),
        ("sensor_testable", "yes"),
    ):
        with pytest.raises(ValueError, match=entry["id"]):
            cat._build({**entry, field: value}, labels)
