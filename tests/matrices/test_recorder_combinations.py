"""The recorder role's combination matrix: golden-recorder faults two and three at a time,
each row checked against what its members declare alone and the declared interactions."""

from __future__ import annotations

import pytest

from conformance.matrices.recorder_combinations import (
    CI_COMBINATIONS,
    KNOWN_OPEN,
    combo_row,
    sample,
)
from conformance.recorder.faults import RECORDER_FAULTS, composition_conflict
from conformance.recorder.interactions import RECORDER_INTERACTIONS


@pytest.mark.parametrize("faults", CI_COMBINATIONS, ids=",".join)
def test_recorder_combination_is_explained_by_its_members(faults):
    row = combo_row(faults)
    assert row.clean, row.explain()


@pytest.mark.slow
@pytest.mark.parametrize(
    "faults", [tuple(sorted(i.members)) for i in RECORDER_INTERACTIONS], ids=",".join
)
def test_each_declared_interaction_row_is_clean(faults):
    """Every interaction's own row, as found (seeds 1, 20, 21)."""
    row = combo_row(faults)
    assert row.clean, row.explain()


@pytest.mark.slow
@pytest.mark.parametrize("faults", list(KNOWN_OPEN), ids=",".join)
def test_known_open_rows_are_still_open(faults):
    """Strict: a row that turns clean must leave KNOWN_OPEN (its class was fixed)."""
    row = combo_row(faults)
    assert not row.clean, f"{row.explain()}: fixed? remove it from KNOWN_OPEN"


def test_interactions_name_faults_that_compose():
    for i in RECORDER_INTERACTIONS:
        assert i.members <= set(RECORDER_FAULTS), i.members
        assert composition_conflict(tuple(sorted(i.members))) is None, i.members
        violates = {r for f in i.members for r in RECORDER_FAULTS[f].violates}
        owned = violates | {r for f in i.members for r in RECORDER_FAULTS[f].inconclusive}
        assert set(i.removes) <= owned, i.members  # only what a member declares is masked
        assert not set(i.adds) & violates, i.members


def test_the_recorder_sampler_is_seeded():
    assert sample(5, 2, 3) == sample(5, 2, 3) != sample(5, 2, 4)


def test_the_cli_runs_recorder_combinations(capsys):
    """``matrix --role recorder --combinations N``: the rows, then the totals (exit 0 clean)."""
    from conformance.cli import main

    combo = sample(1, 2, 5)[0]
    assert main(["matrix", "--role", "recorder", "--combinations", "1", "--seed", "5"]) == 0
    out = capsys.readouterr()
    assert ",".join(combo) in out.err
    assert "1/1 combinations clean" in out.out
    assert main(["matrix", "--role", "recorder"]) == 4  # single recorder faults: pytest


def test_the_cli_runs_every_composing_pair_with_all_pairs(capsys, monkeypatch):
    """``matrix --role recorder --all-pairs``: every pair that composes, not a drawn few (the
    rows themselves stubbed to the first two pairs' here: the whole matrix is 658 runs)."""
    from conformance.cli import main
    from conformance.matrices import recorder_combinations

    ran: list[tuple[str, ...]] = []
    every = recorder_combinations.all_pairs()
    monkeypatch.setattr(recorder_combinations, "all_pairs", lambda: every[:2])
    real = recorder_combinations.combination_matrix

    def spy(combos, processes=1, progress=None):
        ran.extend(combos)
        return real(combos, 1, progress)

    monkeypatch.setattr(recorder_combinations, "combination_matrix", spy)
    assert main(["matrix", "--role", "recorder", "--all-pairs", "--jobs", "1"]) == 0
    assert ran == every[:2]
    out = capsys.readouterr()
    assert "every composing pair, 2" in out.err and "2/2 combinations clean" in out.out
    assert main(["matrix", "--all-pairs"]) == 4  # the sensor role has no such list
    assert main(["matrix", "--role", "recorder", "--all-pairs", "--combinations", "3"]) == 4
