"""The dataclass methods' code cache (``conformance.dataclass_code``): a class made through
it has the very methods ``exec`` of their source gives, the table survives a process and
refuses a file it cannot trust, and nothing is written where bytecode may not be."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from dataclasses import FrozenInstanceError, InitVar, dataclass, field
from importlib.util import MAGIC_NUMBER
from typing import ClassVar

import pytest

from conformance import dataclass_code
from conformance.dataclass_code import CodeCache, read_table

METHODS = ("__init__", "__repr__", "__eq__", "__hash__", "__setattr__", "__delattr__",
           "__lt__", "__le__", "__gt__", "__ge__")  # fmt: skip


def kinds_of_class():
    """Dataclasses using the features whose generated code differs: defaults, factories,
    frozen, order, slots, keyword-only fields, InitVar, ClassVar, __post_init__, unsafe hash."""

    @dataclass
    class Plain:
        a: int
        b: str = "x"
        c: list[int] = field(default_factory=list)

    @dataclass(frozen=True, order=True)
    class Frozen:
        a: float
        b: tuple[int, ...] = ()
        hidden: int = field(default=0, repr=False, compare=False)

    @dataclass(slots=True, kw_only=True)
    class Slotted:
        a: int
        b: int = 2

    @dataclass(unsafe_hash=True)
    class Hashed:
        a: int
        scale: InitVar[int] = 1
        unit: ClassVar[str] = "ms"

        def __post_init__(self, scale: int) -> None:
            self.a *= scale

    return Plain, Frozen, Slotted, Hashed


def made_with(cache: CodeCache | None):
    """The classes of :func:`kinds_of_class` made with ``cache`` standing in for exec (None:
    the builtin, as Python makes them)."""
    before = dataclasses.__dict__.get("exec")
    if cache is None:
        dataclasses.__dict__.pop("exec", None)
    else:
        dataclasses.exec = cache.exec
    try:
        return kinds_of_class()
    finally:
        if before is None:
            dataclasses.__dict__.pop("exec", None)
        else:
            dataclasses.exec = before


def test_a_class_made_through_the_cache_has_the_methods_exec_gives(tmp_path):
    cache = CodeCache(tmp_path / "table.marshal")
    for pass_ in ("compiled", "from the table"):
        cached = made_with(cache)
        plain = made_with(None)
        for mine, theirs in zip(cached, plain, strict=True):
            for name in METHODS:
                a, b = mine.__dict__.get(name), theirs.__dict__.get(name)
                assert (a is None) == (b is None), (pass_, mine, name)
                if a is not None:
                    assert a.__code__ == b.__code__, (pass_, mine, name)
                    assert a.__qualname__ == b.__qualname__
                    assert a.__annotations__.keys() == b.__annotations__.keys()
        compiled = cache.compiled
        if pass_ == "compiled":
            assert compiled > 10
            cache.compiled = 0
        else:
            assert compiled == 0  # every method's code came from the table
    Plain, Frozen, Slotted, Hashed = cached
    assert repr(Plain(1)).endswith("Plain(a=1, b='x', c=[])")
    assert Plain(1) == Plain(1) and Plain(1) != Plain(2)
    assert Frozen(1.0) < Frozen(2.0) and hash(Frozen(1.0, (1,), 5)) == hash(Frozen(1.0, (1,), 6))
    with pytest.raises(FrozenInstanceError):
        Frozen(1.0).a = 2.0  # type: ignore[misc]
    with pytest.raises(TypeError):
        Slotted(1)  # type: ignore[misc]
    assert Slotted(a=1).b == 2 and not hasattr(Slotted(a=1), "__dict__")
    assert Hashed(2, 3).a == 6 and hash(Hashed(6)) == hash(Hashed(6))


def test_the_table_survives_the_process_and_keeps_what_was_used_first(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    path = tmp_path / "table.marshal"
    first = CodeCache(path)
    ns: dict = {}
    first.exec("def f():\n return 41 + 1\n", ns)
    assert ns["f"]() == 42 and first.compiled == 1
    assert first.save() and not first.save()  # nothing new: nothing written
    second = CodeCache(path)
    ns = {}
    second.exec("def f():\n return 41 + 1\n", ns)
    assert ns["f"]() == 42 and second.compiled == 0
    monkeypatch.setattr(dataclass_code, "LIMIT", 2)
    for n in range(3):
        second.exec(f"x{n} = {n}\n", {})
    assert second.save()
    kept = read_table(path)
    assert list(kept) == ["def f():\n return 41 + 1\n", "x0 = 0\n"]


def test_no_table_is_written_where_bytecode_may_not_be(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    cache = CodeCache(tmp_path / "table.marshal")
    cache.exec("y = 1\n", {})
    assert not cache.save() and not (tmp_path / "table.marshal").exists()


@pytest.mark.parametrize(
    "content", [b"", b"not a table", MAGIC_NUMBER + b"\x00garbage", b"\x00\x00\r\n" + b"x" * 9]
)
def test_a_file_that_is_not_this_interpreters_table_is_an_empty_one(tmp_path, content):
    path = tmp_path / "table.marshal"
    path.write_bytes(content)
    assert read_table(path) == {}
    assert read_table(tmp_path / "missing") == {}


def test_the_command_line_installs_it_and_the_plugin_alone_does_not():
    """``conformance.cli`` stands the cache in for ``exec`` in dataclasses before it imports
    the rest of the tool; a pytest session elsewhere that only loads the plugin (it is an
    installed entry point) keeps the builtin and writes nothing into the package."""
    probe = "import dataclasses, {}; print('exec' in vars(dataclasses))"
    seen = {
        module: subprocess.run(
            [sys.executable, "-c", probe.format(module)],
            capture_output=True,
            text=True,
            timeout=60,
            check=True,
        ).stdout.strip()  # fmt: skip
        for module in ("conformance.plugin", "conformance.cli")
    }
    assert seen == {"conformance.plugin": "False", "conformance.cli": "True"}, seen


def test_a_whole_sim_process_reads_every_method_from_the_table(tmp_path):
    """The second of two ``--port sim`` processes compiles no dataclass method: every one
    it defines was written to the table by the first (bytecode writing on, as in CI; a table
    of the test's own, swapped in before the command line makes its first dataclass)."""
    import os

    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    script = (
        "import atexit, sys\n"
        "from pathlib import Path\n"
        "from conformance import dataclass_code as d\n"
        "d.install()\n"
        "out = sys.argv.pop(1)\n"
        "d.CACHE.path = Path(sys.argv.pop(1))\n"
        "d.CACHE.code = d.read_table(d.CACHE.path)\n"
        "atexit.register(lambda: open(out, 'w').write(str(d.CACHE.compiled)))\n"
        "from conformance.cli import main\n"
        "main()\n"
    )
    counts = []  # methods each process compiled
    for n in range(2):
        out = tmp_path / f"compiled{n}"
        subprocess.run(
            [sys.executable, "-c", script, str(out), str(tmp_path / "table.marshal"),
             "--port", "sim", "-k", "test_query_address",
             "--report-dir", str(tmp_path / f"run{n}"), "--plan", "never"],
            capture_output=True, text=True, timeout=120, cwd=tmp_path, env=env, check=True,
        )  # fmt: skip
        counts.append(int(out.read_text()))
    assert counts[0] > 100 and counts[1] == 0, counts
