"""pytest-html's page template read when the page is rendered and compiled once per
installation (:mod:`conformance.reports.page_template`) renders the page pytest-html's own
reader renders: cache cold, warm, stale or unwritable."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from pytest_html import plugin as page_plugin
from pytest_html import util

from conformance.reports import page_template

SEARCH = [Path(util.__file__).parent / "resources"]

#: what pytest-html hands its template (the include of app.js is rendered too)
VALUES = {
    "title": "t", "date": "01-Jan-2026", "time": "00:00:00", "version": "4",
    "styles": "b{}", "run_count": "1 test took 1 ms.", "running_state": "finished",
    "self_contained": True, "outcomes": {"passed": {"label": "Passed", "value": 1}},
    "test_data": '{"tests": {}}', "table_head": ["<th>Result</th>"],
    "additional_summary": {"prefix": ["<p>a</p>"], "summary": [], "postfix": []},
}  # fmt: skip


@pytest.fixture
def writing(monkeypatch) -> None:
    """Bytecode may be written (the shell running the tests may say otherwise)."""
    monkeypatch.setattr(sys, "dont_write_bytecode", False)


def _files(folder: Path) -> list[Path]:
    return sorted(folder.glob("page_template.*.jinja2c"))


def _later(folder: Path) -> page_template.TemplateWhenRendered:
    read = page_template.with_installed_cache(util._read_template, util, folder)
    return page_template.TemplateWhenRendered(read, (SEARCH,), {})


def test_the_page_is_pytest_htmls_page_cache_cold_and_warm(tmp_path: Path, writing) -> None:
    page = util._read_template(SEARCH).render(**VALUES)
    cold = _later(tmp_path)
    assert cold.render(**VALUES) == page
    assert len(_files(tmp_path)) == 2  # index.jinja2 and the app.js it includes
    warm = _later(tmp_path)  # another process's read: from the files
    assert warm.render(**VALUES) == page and warm.render(**VALUES) == page
    assert util.Environment.__name__ == "Environment"  # pytest-html's own class again


def test_nothing_is_read_until_a_page_is_made(tmp_path: Path) -> None:
    reads: list[object] = []

    def read(*args: object, **kwargs: object):
        reads.append(args)
        return util._read_template(*args, **kwargs)

    later = page_template.TemplateWhenRendered(read, (SEARCH,), {})
    assert reads == []
    later.render(**VALUES)
    later.render(**VALUES)
    assert len(reads) == 1


def test_a_stale_or_damaged_file_is_compiled_again(tmp_path: Path, writing) -> None:
    page = util._read_template(SEARCH).render(**VALUES)
    _later(tmp_path).render(**VALUES)
    assert len(_files(tmp_path)) == 2
    for path in _files(tmp_path):
        path.write_bytes(path.read_bytes()[:40] + b"damaged")
    assert _later(tmp_path).render(**VALUES) == page
    for path in _files(tmp_path):
        path.write_bytes(b"not jinja2's at all")
    assert _later(tmp_path).render(**VALUES) == page


def test_no_file_where_bytecode_is_not_written(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    assert _later(tmp_path).render(**VALUES) == util._read_template(SEARCH).render(**VALUES)
    assert _files(tmp_path) == []


def test_an_unwritable_folder_is_no_failure(tmp_path: Path, writing) -> None:
    missing = tmp_path / "no" / "such" / "folder"
    page = util._read_template(SEARCH).render(**VALUES)
    assert _later(missing).render(**VALUES) == page
    assert not missing.exists()


def test_the_template_reader_is_put_back() -> None:
    """Deferring replaces pytest-html's reader for the session only; a reader that is not
    pytest-html's own (deferred already, or another version's) is left alone."""
    own = page_plugin._read_template
    undo = page_template.template_when_rendered()
    assert undo is not None
    try:
        assert page_plugin._read_template is not own
        later = page_plugin._read_template(SEARCH)
        assert isinstance(later, page_template.TemplateWhenRendered)
        assert page_template.template_when_rendered() is None  # not deferred twice
    finally:
        undo()
    assert page_plugin._read_template is own


def test_a_cache_file_is_named_by_versions_and_template(tmp_path: Path, writing) -> None:
    import jinja2
    from pytest_html import __version__

    _later(tmp_path).render(**VALUES)
    names = [p.name for p in _files(tmp_path)]
    assert len(names) == 2
    tag = f"{sys.implementation.cache_tag}.jinja2-{jinja2.__version__}.html-{__version__}"
    assert all(n.startswith(f"page_template.{tag}.") for n in names), names


#: a fresh interpreter: pytest-html's helper loaded without jinja2, then its page rendered
#: (pytest-html's own reader, and the cached one); prints whether jinja2 was loaded before
#: the first render, then the two pages
WITHOUT_JINJA2 = """
import json, sys
from pathlib import Path
from conformance.reports import page_template
loaded = page_template.page_plugin_without_jinja2()
from pytest_html import plugin, util
before = "jinja2" in sys.modules or "markupsafe" in sys.modules
search, values, folder = json.loads(sys.argv[1])
own = util._read_template(search).render(**values)
read = page_template.with_installed_cache(util._read_template, util, Path(folder))
cached = page_template.TemplateWhenRendered(read, (search,), {}).render(**values)
print(json.dumps([loaded, before, own, cached]))
"""


def test_pytest_html_loads_without_jinja2_and_renders_the_same_page(tmp_path: Path) -> None:
    import json
    import os
    import subprocess

    page = util._read_template(SEARCH).render(**VALUES)
    given = json.dumps([[str(p) for p in SEARCH], VALUES, str(tmp_path)])
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    done = subprocess.run(
        [sys.executable, "-c", WITHOUT_JINJA2, given], capture_output=True, text=True,
        env=env, check=True, timeout=120,
    )  # fmt: skip
    loaded, before, own, cached = json.loads(done.stdout.strip().splitlines()[-1])
    assert loaded is True and before is False
    assert own == page and cached == page


def test_the_stand_in_answers_no_probe() -> None:
    """The import system's and introspection's probes (``__path__``, ``__wrapped__``) get
    no answer from a stand-in, so nothing but a real use loads jinja2."""
    assert not hasattr(page_template.JinjaName("Environment"), "__wrapped__")
    with pytest.raises(AttributeError):
        page_template._jinja_name("__path__")
    assert page_template._jinja_name("Environment").name == "Environment"


def test_nothing_is_stood_in_where_pytest_html_is_loaded_already() -> None:
    assert "pytest_html.util" in sys.modules  # this module imported it
    assert page_template.page_plugin_without_jinja2() is False
    assert util.Environment.__module__.startswith("jinja2")
