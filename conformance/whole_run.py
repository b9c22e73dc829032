"""Whole-run cases: judgments over everything a run sent (every reply's framing, every
character gap), which the plugin runs after every other case.

Every other case asks for its own stimuli (the session's cache makes each once), so its
verdict does not depend on where it runs. A whole-run case judges the run's transcript as a
whole, so it must come after the traffic it judges: rather than rely on file names sorting it
last, the plugin moves it behind the other cases after every plugin that reorders or selects
(``-p randomly``, ``-k``, ``--req``) has had its say. Such a case also asks for the standard
stimuli itself, so a partial run that selects it still has every kind of reply to judge.
"""

from __future__ import annotations

from collections.abc import Generator

import pytest

MARKER = "whole_run"
MARKER_HELP = f"{MARKER}: judges the whole run's transcript; runs after every other case"


def is_whole_run(item: pytest.Item) -> bool:
    return item.get_closest_marker(MARKER) is not None


def last(items: list[pytest.Item]) -> None:
    """Move the whole-run cases behind the others, keeping each group's own order."""
    items[:] = [i for i in items if not is_whole_run(i)] + [i for i in items if is_whole_run(i)]


class WholeRunLast:
    """A pytest plugin object: its hook wraps every other ``pytest_collection_modifyitems``,
    so the whole-run cases end up last whatever a reordering plugin did before."""

    @pytest.hookimpl(wrapper=True)
    def pytest_collection_modifyitems(self, items: list[pytest.Item]) -> Generator[None]:
        result = yield
        last(items)
        return result
