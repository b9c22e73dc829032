"""The main command's console where its output is no terminal (a log, a pipe, CI), without rich.

Off a terminal rich writes a plain line of text: no colour, no bar, no wrapping (the tool's
consoles soft-wrap there). Yet importing rich.console cost every such run about 30 ms, a
fortieth of a whole ``sdi12-conform --port sim`` process (issue 22), for lines that are the
text itself. :class:`PlainConsole` writes those lines as rich writes them (the same text,
emoji codes replaced by rich's own function, the control codes rich strips stripped, a flush
per call, a broken pipe silenced) and hands anything else to a rich console made on first
need: markup, a tab, another control code, a renderable, wrapping asked for.
:func:`plain_output` says where it may stand in: where rich itself would see no terminal and
no environment variable could make it see one.
"""

from __future__ import annotations

import builtins
import os
import re
import sys
from collections.abc import Callable
from typing import Any, TextIO

#: the control codes rich strips from printed text (rich.control.STRIP_CONTROL_CODES: bell,
#: backspace, vertical tab, form feed, carriage return)
STRIPPED = {7: None, 8: None, 11: None, 12: None, 13: None}

#: finds text that rich's emoji pattern (``:(\S*?)(?:-(emoji|text))?:``) could match
EMOJI_CODE = re.compile(r":\S*:").search

#: environment variables with which rich may treat any output as a terminal (or Jupyter's)
TERMINAL_ENV = ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE", "JUPYTER_COLUMNS")


def plain_output(stream: TextIO) -> bool:
    """Whether rich would write plain text to ``stream``: no terminal, nothing in the
    environment that could make it one, not Windows (its legacy console), not IDLE nor
    Jupyter (which rich detects apart)."""
    if sys.platform == "win32" or any(name in os.environ for name in TERMINAL_ENV):
        return False
    if hasattr(builtins, "get_ipython") or "idlelib" in sys.modules:
        return False
    try:
        return not stream.isatty()
    except (AttributeError, ValueError):
        return False


def _plain_text(objects: tuple[Any, ...], sep: str, markup: bool | None) -> str | None:
    """The text rich would write for ``objects``, or None where only rich can say."""
    if not all(isinstance(o, str) for o in objects):
        return None
    text = sep.join(objects)
    if markup is not False and "[" in text:
        return None
    if any(c < " " and c != "\n" for c in text.translate(STRIPPED)) or "\x7f" in text:
        return None  # a tab (expanded), an escape: rich's rendering, not ours
    if EMOJI_CODE(text):  # what rich's emoji codes could match (``:name:``): its own function
        from rich._emoji_replace import _emoji_replace

        text = _emoji_replace(text)
    return text.translate(STRIPPED)


class PlainConsole:
    """What the main command asks of a rich ``Console`` off a terminal: ``print``,
    ``is_terminal``, ``quiet``, ``file``. ``rich_console`` makes the rich console it hands
    the rest to; ``on_broken_pipe`` is called when the reader went away."""

    is_terminal = False

    def __init__(
        self,
        rich_console: Callable[[], Any],
        on_broken_pipe: Callable[[], None],
        *,
        stderr: bool = False,
    ) -> None:
        self.stderr = stderr
        self.quiet = False
        self._make_rich = rich_console
        self._rich: Any = None
        self.on_broken_pipe = on_broken_pipe

    @property
    def file(self) -> TextIO:
        """The stream at the time of writing (as rich's: pytest's capture may swap it)."""
        return sys.stderr if self.stderr else sys.stdout

    def rich(self) -> Any:
        """The rich console for what a plain line cannot show (made once, on first need)."""
        if self._rich is None:
            self._rich = self._make_rich()
            self._rich.quiet = self.quiet
        return self._rich

    def print(
        self,
        *objects: Any,
        sep: str = " ",
        end: str = "\n",
        markup: bool | None = None,
        soft_wrap: bool | None = None,
        **options: Any,
    ) -> None:
        """Write ``objects`` as rich would off a terminal (``style`` and ``highlight`` draw
        nothing there); anything else through rich."""
        text = None
        if soft_wrap is not False and not set(options) - {"style", "highlight"}:
            text = _plain_text(objects, sep, markup)
        if text is None:
            console = self.rich()
            console.quiet = self.quiet
            console.print(*objects, sep=sep, end=end, markup=markup, soft_wrap=soft_wrap,
                          **options)  # fmt: skip
            self.quiet = console.quiet
            return
        if self.quiet:
            return
        try:
            self.file.write(text + end)
            self.file.flush()
        except BrokenPipeError:
            self.on_broken_pipe()
