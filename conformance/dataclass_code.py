"""The code of generated dataclass methods, compiled once per installation instead of once
per process.

``@dataclass`` writes each class's ``__init__``, ``__repr__``, ``__eq__``, ``__hash__`` (and
a frozen class's ``__setattr__``/``__delattr__``) as Python source and compiles it when the
class is defined: in every process, for every class, although the source is the same each
time. A ``--port sim`` process defines about 150 dataclasses (78 of the tool's, pytest's and
hypothesis's the rest), and compiling their 680 methods was 6.9% of its instructions.

This is what ``__pycache__`` does for modules, done for those methods: :class:`CodeCache`
stands in for ``exec`` inside :mod:`dataclasses` (its module-level name, so nothing else
changes), looks the source up in a table of code objects read from one file beside the
package's bytecode, compiles only what is not there, and at exit writes the table back when
it learned something (never when bytecode is not to be written: ``PYTHONDONTWRITEBYTECODE``,
``-B``). The code object run is the one ``exec(source)`` would have compiled (the same
source, file name ``<string>``, no inherited ``__future__`` flags, the interpreter's own
optimisation level, in the file's name with the interpreter's cache tag), so every class,
method and error is what it was; ``tests/test_dataclass_code.py`` compares them.
"""

from __future__ import annotations

import atexit
import builtins
import contextlib
import dataclasses
import marshal
import sys
from importlib.util import MAGIC_NUMBER
from itertools import chain
from pathlib import Path
from types import CodeType
from typing import Any

#: the sources kept at most (the ones this process used first): the tool's own, pytest's and
#: hypothesis's classes need about 700; a test suite defining its own adds to them
LIMIT = 4096

#: the table's file: the interpreter's cache tag and optimisation level in its name, as a
#: module's bytecode has them, and the bytecode's magic number at its head
PATH = (
    Path(__file__).resolve().parent
    / "__pycache__"
    / f"dataclass_code.{sys.implementation.cache_tag}.opt{sys.flags.optimize}.marshal"
)


class CodeCache:
    """Code objects by the source text they were compiled from (see the module's doc)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.code: dict[str, CodeType] = read_table(path)
        #: the sources this process asked for, in order (the ones a saved table keeps first)
        self.used: dict[str, None] = {}
        self.compiled = 0  # sources this process compiled (not in the table it read)

    def exec(self, source: Any, globals: dict | None = None, locals: Any = None, /) -> None:
        """``exec`` as :mod:`dataclasses` calls it (source text, its globals, a namespace):
        the cached code object for a text, compiled here on a miss."""
        if globals is None:  # exec's own default: the calling module's globals
            globals = vars(dataclasses)
        if type(source) is str:
            code = self.code.get(source)
            if code is None:
                code = compile(source, "<string>", "exec", dont_inherit=True)
                self.compiled += 1
                self.code[source] = code
            self.used[source] = None
            source = code
        builtins.exec(source, globals, globals if locals is None else locals)

    def save(self) -> bool:
        """Write the table if this process compiled anything and may write bytecode: the
        sources it used first, then those another process wrote meanwhile, then the rest it
        read, up to :data:`LIMIT` (processes writing at once: the last one's table stands,
        and what it lacks is compiled once more)."""
        if not self.compiled or sys.dont_write_bytecode:
            return False
        written = read_table(self.path)
        kept: dict[str, CodeType] = {}
        for source in chain(self.used, written, self.code):
            if len(kept) >= LIMIT:
                break
            if source not in kept:
                kept[source] = self.code[source] if source in self.code else written[source]
        data = MAGIC_NUMBER + marshal.dumps(kept)
        try:
            from .atomic import atomic_path

            self.path.parent.mkdir(exist_ok=True)
            with atomic_path(self.path) as temp:
                temp.write_bytes(data)
        except OSError:  # an install the user cannot write to: compiled again next time
            return False
        self.compiled = 0
        return True


def read_table(path: Path) -> dict[str, CodeType]:
    """The table a file holds; empty when there is none, or it is another interpreter's
    (its magic number), or it cannot be read as one."""
    try:
        data = path.read_bytes()
    except OSError:
        return {}
    if not data.startswith(MAGIC_NUMBER):
        return {}
    try:
        table = marshal.loads(data[len(MAGIC_NUMBER) :])
    except (EOFError, ValueError, TypeError):
        return {}
    if not isinstance(table, dict):
        return {}
    return {s: c for s, c in table.items() if type(s) is str and type(c) is CodeType}


#: the process's cache, once :func:`install` ran
CACHE: CodeCache | None = None


def install() -> CodeCache:
    """Stand the cache in for ``exec`` in :mod:`dataclasses` (once per process) and write
    what it learned at exit."""
    global CACHE
    if CACHE is None:
        CACHE = CodeCache(PATH)
        dataclasses.exec = CACHE.exec  # type: ignore[attr-defined]
        atexit.register(_save_quietly, CACHE)
    return CACHE


def uninstall() -> None:
    """``exec`` in :mod:`dataclasses` is the builtin again (tests compare the two)."""
    global CACHE
    if CACHE is not None:
        with contextlib.suppress(AttributeError):
            del dataclasses.exec  # type: ignore[attr-defined]
        atexit.unregister(_save_quietly)
        CACHE = None


def _save_quietly(cache: CodeCache) -> None:
    with contextlib.suppress(Exception):  # a cache: never a reason for an exit to fail
        cache.save()
