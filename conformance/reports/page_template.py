"""pytest-html's page template: read when the page is rendered, compiled once per installation.

pytest-html reads its jinja2 template (``index.jinja2``, and ``app.js`` included in it) when
the session is configured and compiles it to Python code, in every process, although the
template is the same each time: about 13 ms of a ``--port sim`` process, most of it jinja2's
lexer, parser and code generator. Two things change here, neither what the page says:

- :class:`TemplateWhenRendered`: the template is read where the page is rendered, so in the
  main command's process the forked child that renders report.html
  (:mod:`conformance.reports.html_aside`) reads it and the parent, the critical path, never
  does;
- :func:`installed_cache`: jinja2's own bytecode cache (the compiled template's code object,
  checked against the template's source) kept beside the package's bytecode, as
  :mod:`conformance.dataclass_code` keeps generated dataclass methods: the same code
  ``Environment.compile`` makes, unmarshalled (under 1 ms) instead of compiled; written only
  where bytecode may be written, never a failure when it cannot be.

- :func:`page_plugin_without_jinja2`: in the main command's process pytest-html's helper
  module is loaded with stand-ins for the three jinja2 names it binds, each loading jinja2
  on its first use: only the process that reads the template (the forked child) loads
  jinja2 and markupsafe (about 20 ms), the parent never does.

pytest-html's own reader still builds the environment with its own options
(:func:`template_when_rendered` only lends it the cache), so a page is what pytest-html makes.
``tests/reports/test_page_template.py`` compares the pages.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: the folder of the cache's files: the package's own bytecode folder
FOLDER = Path(__file__).resolve().parent.parent / "__pycache__"


def installed_cache(folder: Path = FOLDER) -> Any:
    """A :class:`jinja2.BytecodeCache` keeping compiled templates in ``folder``, one file per
    template, named by the interpreter's cache tag, jinja2's and pytest-html's versions and
    jinja2's key for the template (its name and file); jinja2 checks each file's format and
    the template source's checksum itself and compiles again where either differs."""
    import jinja2
    from jinja2.bccache import Bucket, BytecodeCache

    try:
        from pytest_html import __version__ as page_version
    except ImportError:  # pragma: no cover - the cache serves pytest-html's template only
        page_version = "none"
    tag = f"{sys.implementation.cache_tag}.jinja2-{jinja2.__version__}.html-{page_version}"

    class Cache(BytecodeCache):
        def _path(self, bucket: Bucket) -> Path:
            return folder / f"page_template.{tag}.{bucket.key}.jinja2c"

        def load_bytecode(self, bucket: Bucket) -> None:
            try:
                with self._path(bucket).open("rb") as f:
                    bucket.load_bytecode(f)  # another format or source: jinja2 resets it
            except OSError:
                return  # none yet: compiled and written
            except Exception:  # noqa: BLE001 - a damaged file (cut short): compiled again
                bucket.reset()

        def dump_bytecode(self, bucket: Bucket) -> None:
            if sys.dont_write_bytecode:
                return
            path = self._path(bucket)
            part = path.with_name(f"{path.name}.{os.getpid()}")
            try:
                with part.open("wb") as f:
                    bucket.write_bytecode(f)
                os.replace(part, path)  # whole or not at all for a reader at the same time
            except OSError:  # a folder the user cannot write: compiled again next time
                with contextlib.suppress(OSError):
                    part.unlink()

    return Cache()


class TemplateWhenRendered:
    """pytest-html's page template, read (through ``read``, pytest-html's own reader) on
    the first render, not when the session is configured."""

    def __init__(self, read: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]):
        self._read = read
        self._args = args
        self._kwargs = kwargs
        self._template: Any = None

    def render(self, *args: Any, **kwargs: Any) -> str:
        if self._template is None:
            self._template = self._read(*self._args, **self._kwargs)
        return self._template.render(*args, **kwargs)


def with_installed_cache(
    read: Callable[..., Any], util: Any, folder: Path = FOLDER
) -> Callable[..., Any]:
    """pytest-html's reader ``read`` run with ``util.Environment`` (the class it builds its
    environment from) lending the environment :func:`installed_cache` where pytest-html
    gives it none; the reader's own options otherwise."""

    def cached_read(*args: Any, **kwargs: Any) -> Any:
        environment = util.Environment
        real = environment.real() if isinstance(environment, JinjaName) else environment

        class CachedEnvironment(real):  # type: ignore[misc, valid-type]
            def __init__(self, *a: Any, **k: Any) -> None:
                if k.get("bytecode_cache") is None:
                    k["bytecode_cache"] = installed_cache(folder)
                super().__init__(*a, **k)

        util.Environment = CachedEnvironment
        try:
            return read(*args, **kwargs)
        finally:
            util.Environment = environment

    return cached_read


def template_when_rendered() -> Callable[[], None] | None:
    """Make pytest-html's configure hand its report a :class:`TemplateWhenRendered` that
    reads through :func:`with_installed_cache` (call it before that hook runs); the function
    that undoes it (at the session's end), or None where pytest-html is not loaded or its
    reader is not the one this knows."""
    page_plugin = sys.modules.get("pytest_html.plugin")
    util = sys.modules.get("pytest_html.util")
    read = getattr(page_plugin, "_read_template", None)
    if read is None or util is None or read is not getattr(util, "_read_template", None):
        return None  # another pytest-html, or already deferred: leave it
    if not isinstance(getattr(util, "Environment", None), (type, JinjaName)):
        return None
    cached_read = with_installed_cache(read, util)

    def deferred(*args: Any, **kwargs: Any) -> TemplateWhenRendered:
        return TemplateWhenRendered(cached_read, args, kwargs)

    page_plugin._read_template = deferred  # type: ignore[union-attr]

    def undo() -> None:
        page_plugin._read_template = read  # type: ignore[union-attr]

    return undo


class JinjaName:
    """Stands for one name of jinja2 bound by pytest-html's helper module
    (:func:`page_plugin_without_jinja2`): jinja2 is imported when the name is first called
    or looked into, and the call is jinja2's own."""

    def __init__(self, name: str) -> None:
        self.name = name

    def real(self) -> Any:
        return getattr(importlib.import_module("jinja2"), self.name)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.real()(*args, **kwargs)

    def __getattr__(self, attribute: str) -> Any:
        if attribute.startswith("__"):  # a probe (copy, inspect) does not load jinja2
            raise AttributeError(attribute)
        return getattr(self.real(), attribute)


def _jinja_name(name: str) -> JinjaName:
    """The stand-in module's ``__getattr__``: a :class:`JinjaName` for a name it binds, no
    answer for the import system's probes (``__path__``, ``__spec__``...)."""
    if name.startswith("__"):
        raise AttributeError(name)
    return JinjaName(name)


def page_plugin_without_jinja2() -> bool:
    """Load pytest-html's helper module (``pytest_html.util``, which the plugin imports)
    with :class:`JinjaName` stand-ins for what it takes from jinja2, so loading pytest-html
    does not load jinja2; whether it did (not where pytest-html or jinja2 is loaded
    already, or pytest-html is missing). A helper module that binds more of jinja2 gets a
    stand-in for each; jinja2 itself stays out of ``sys.modules`` until one is used."""
    if "pytest_html.util" in sys.modules or "jinja2" in sys.modules:
        return False
    stand_in = types.ModuleType("jinja2")
    stand_in.__getattr__ = _jinja_name  # type: ignore[method-assign]  # any name it binds
    sys.modules["jinja2"] = stand_in
    try:
        importlib.import_module("pytest_html.util")
    except ImportError:
        return False
    finally:
        if sys.modules.get("jinja2") is stand_in:
            del sys.modules["jinja2"]
    return True
