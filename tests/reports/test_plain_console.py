"""The main command's plain console writes, off a terminal, exactly what rich's console
writes there, and stands in only where rich would see no terminal."""

from __future__ import annotations

import io
import os
import random
import sys

import pytest
from rich.console import Console
from rich.table import Table

from conformance.reports import plain_console
from conformance.reports.plain_console import PlainConsole, plain_output

#: characters that change what rich writes: markup, emoji codes, tabs, the control codes it
#: strips and one it does not, wide and combining characters, newlines
ALPHABET = list("ab0 :-_[]/\\\t\r\n\x07\x08\x0b\x0c\x1b\x7fé中\u0301!~") + [
    ":smile:", ":thumbs_up-text:", ":red_heart-emoji:", "[bold]", "[/]", "rfc2217://h:4001",
]  # fmt: skip
KWARGS = [
    {}, {"markup": False}, {"highlight": False}, {"markup": False, "highlight": False},
    {"style": "bold yellow", "markup": False}, {"soft_wrap": True}, {"end": ""},
    {"sep": "|"}, {"markup": False, "highlight": False, "soft_wrap": True},
]  # fmt: skip


def _rich_writes(objects: tuple, kwargs: dict) -> str:
    out = io.StringIO()
    try:
        Console(file=out, soft_wrap=True, _environ={}).print(*objects, **kwargs)
    except Exception as exc:  # bad markup: the same error both ways
        return f"{type(exc).__name__}: {exc}"
    return out.getvalue()


#: how many prints :func:`_plain_writes` made without rich
WITHOUT_RICH: list[int] = [0]


def _plain_writes(objects: tuple, kwargs: dict, monkeypatch: pytest.MonkeyPatch) -> str:
    out = io.StringIO()
    monkeypatch.setattr(sys, "stdout", out)
    made: list[Console] = []

    def rich() -> Console:
        made.append(Console(file=out, soft_wrap=True, _environ={}))
        return made[-1]

    try:
        PlainConsole(rich, lambda: None).print(*objects, **kwargs)
    except Exception as exc:
        return f"{type(exc).__name__}: {exc}"
    WITHOUT_RICH[0] += not made
    return out.getvalue()


def test_plain_lines_are_richs_lines(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = random.Random(22)
    before = WITHOUT_RICH[0]
    for _ in range(600):
        objects = tuple(
            "".join(rng.choice(ALPHABET) for _ in range(rng.randrange(0, 12)))
            for _ in range(rng.choice([0, 1, 1, 1, 2]))
        )
        kwargs = rng.choice(KWARGS)
        assert _plain_writes(objects, kwargs, monkeypatch) == _rich_writes(objects, kwargs), (
            objects,
            kwargs,
        )
    assert WITHOUT_RICH[0] - before > 150  # most of them plain lines, not rich's


@pytest.mark.parametrize(
    "text",
    ["verdict: COMPLIANT", "[ 1/62] PASS         test_crc_presence", "note: :smile: x",
     "DUT 0 · SDI-12 1.4 · '014CONFORM EMU001100SN0001'", "a\tb", "bell\x07", "esc\x1b[31m",
     "", "line\nline"],
)  # fmt: skip
def test_the_lines_a_run_prints(text: str, monkeypatch: pytest.MonkeyPatch) -> None:
    for kwargs in KWARGS:
        assert _plain_writes((text,), kwargs, monkeypatch) == _rich_writes((text,), kwargs)


def test_a_renderable_goes_to_rich(monkeypatch: pytest.MonkeyPatch) -> None:
    table = Table("a", "b")
    table.add_row("1", "2")
    assert _plain_writes((table,), {}, monkeypatch) == _rich_writes((table,), {})


def test_no_stand_in_where_rich_could_see_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in plain_console.TERMINAL_ENV:
        monkeypatch.delenv(name, raising=False)
    assert plain_output(io.StringIO())
    for name in plain_console.TERMINAL_ENV:
        monkeypatch.setenv(name, "1")
        assert not plain_output(io.StringIO()), name
        monkeypatch.delenv(name)
    monkeypatch.setattr(sys, "platform", "win32")
    assert not plain_output(io.StringIO())
    monkeypatch.setattr(sys, "platform", "linux")
    primary, secondary = os.openpty()
    try:
        with os.fdopen(secondary, "w", closefd=False) as tty:
            assert not plain_output(tty)
    finally:
        os.close(primary)
        os.close(secondary)


class _Gone(io.StringIO):
    def write(self, text: str) -> int:
        raise BrokenPipeError


def test_a_broken_pipe_silences_the_console(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "stdout", _Gone())
    called: list[bool] = []
    console = PlainConsole(lambda: None, lambda: called.append(True))
    console.on_broken_pipe = lambda: (called.append(True), setattr(console, "quiet", True))
    console.print("first")
    console.print("second")
    assert called == [True] and console.quiet
