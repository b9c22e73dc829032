"""The end-of-run section that lists real-time tests skipped because the machine was busy
(``tests/conftest.py``): each with its figure, even with ``-q`` and under pytest-xdist, and
nothing when no test skipped for that reason."""

from __future__ import annotations

import pytest

from tests.support.paths import ROOT, TESTS

CONFTEST = TESTS / "conftest.py"

TINY = """
import pytest

def test_line_fell_behind():
    pytest.skip("the machine was too busy to keep real time: the served line fell "
                "12.5 ms behind its schedule")

def test_without_compiler():
    pytest.skip("no C compiler on PATH")

def test_passes():
    pass
"""


@pytest.fixture
def tiny(pytester: pytest.Pytester) -> pytest.Pytester:
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makepyfile(test_tiny=TINY)
    return pytester


def test_busy_skip_is_listed_with_its_figure_even_with_q(tiny):
    result = tiny.runpytest("-q", "-p", "no:xdist")
    result.assert_outcomes(passed=1, skipped=2)
    result.stdout.fnmatch_lines(
        [
            "*= skipped because the machine was busy: 1 =*",
            "test_tiny.py::test_line_fell_behind: the machine was too busy * 12.5 ms behind*",
        ]
    )
    assert "no C compiler" not in result.stdout.str()  # an ordinary skip is not listed


@pytest.mark.slow  # starts a worker process
def test_busy_skip_is_listed_from_an_xdist_worker(tiny):
    pytest.importorskip("xdist")
    result = tiny.runpytest_subprocess("-q", "-n", "1")
    result.assert_outcomes(passed=1, skipped=2)
    result.stdout.fnmatch_lines(["*test_line_fell_behind: the machine was too busy * 12.5 ms*"])


def test_no_section_when_nothing_skipped_for_a_busy_machine(pytester):
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makepyfile(test_fine="def test_ok():\n    pass\n")
    result = pytester.runpytest("-q", "-p", "no:xdist")
    result.assert_outcomes(passed=1)
    assert "machine was busy" not in result.stdout.str()


def test_every_module_named_first_exists():
    """A module renamed or removed would silently lose its place at the front."""
    from tests.conftest import FIRST

    assert len(set(FIRST)) == len(FIRST)
    missing = [name for name in FIRST if not (ROOT / name).is_file()]
    assert not missing, missing


def test_the_longest_modules_are_collected_first_and_nothing_else_moves(pytester):
    """Collection order is the order CI's xdist workers take the modules in (.ci/test)."""
    from tests.conftest import FIRST

    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    two = "def test_one():\n    pass\n\ndef test_two():\n    pass\n"
    by_name = ["tests/aaa/test_early_by_name.py", "tests/zzz/test_late_by_name.py"]
    for name in [*by_name, FIRST[2], FIRST[0]]:
        path = pytester.path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(two, encoding="utf-8")
    result = pytester.runpytest("--collect-only", "-q", "-p", "no:xdist")
    ids = [line for line in result.stdout.lines if "::test_" in line]
    expected = [FIRST[0], FIRST[2], *by_name]
    assert ids == [f"{m}::{t}" for m in expected for t in ("test_one", "test_two")], ids


def test_a_timed_test_in_a_module_not_naming_its_marker_fails_the_session(pytester):
    """.ci/test's real-time sessions collect only the modules that name ``realtime`` or
    ``quiet`` (tests/conftest.py, TIMED): a real-time test marked from elsewhere would never
    run there, so a session that deselects one stops with a usage error naming it."""
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makepyfile(
        marks="import pytest\n\nLINE = pytest.mark.realtime\n",
        test_hidden="from marks import LINE\n\npytestmark = LINE\n\n"
        "def test_on_a_line():\n    pass\n",
        test_named="import pytest\n\n@pytest.mark.realtime\ndef test_named():\n    pass\n\n"
        "def test_plain():\n    pass\n",
    )
    result = pytester.runpytest("-q", "-p", "no:xdist", "-m", "not realtime")
    assert result.ret == pytest.ExitCode.USAGE_ERROR, result.stdout.str()
    result.stderr.fnmatch_lines(["*do not name their marker*test_hidden.py::test_on_a_line"])
    assert "test_named.py::test_named" not in result.stderr.str()
